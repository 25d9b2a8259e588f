// EvaluationConfig's field table and validation (docs in evaluation_config.hpp).

#include "keyplace/eval/evaluation_config.hpp"

#include <stdexcept>

#include "eval/eval_fields.hpp"

namespace keyplace {

const ConfigFields<EvaluationConfig>& EvaluationConfigFields() {
  using C = EvaluationConfig;
  static const ConfigFields<C> fields = [] {
    ConfigFields<C> table("EvaluationConfig");
    table
        .Double("local_relation_max_dt_s", &C::local_relation_max_dt_s, "s",
                "relations with |t_b - t_a| below this are local, the others loop")
        .Double("relation_stamp_tolerance_s", &C::relation_stamp_tolerance_s, "s",
                "a relation stamp matches the scan with the nearest stamp within this")
        .Double("min_matched_relations", &C::min_matched_relations, "",
                "no relation error when fewer than this fraction of the relations matched")
        .Int("truth_max_gap_scans", &C::truth_max_gap_scans, "",
             "slam loops are checked when their origins are this close to a corrected scan")
        .Double("revisit_radius_m", &C::revisit_radius_m, "m",
                "a localize query is revisitable with a map scan this close to its true pose")
        .Double("revisit_angle_deg", &C::revisit_angle_deg, "deg",
                "... and a heading this close (recall_revisitable)")
        .Double("give_up_m", &C::give_up_m, "m",
                "relocalize: a start without a fix is given up after this odometry distance")
        .Double("follow_m", &C::follow_m, "m",
                "relocalize: fixes are checked over this distance after the first one")
        .Double("revisit_room_m", &C::revisit_room_m, "m",
                "relocalize: a start with a revisit has room with this much path left after it")
        .Double("grid_tolerance_m", &C::grid_tolerance_m, "m",
                "slam --grid: occupied cells agree with the corrected-pose grid within this");
    return table;
  }();
  return fields;
}

void Validate(const EvaluationConfig& config) {
  if (!(config.local_relation_max_dt_s > 0.0)) {
    throw std::invalid_argument("EvaluationConfig.local_relation_max_dt_s must be positive");
  }
  if (!(config.relation_stamp_tolerance_s >= 0.0 && config.relation_stamp_tolerance_s <= 1.0)) {
    throw std::invalid_argument("EvaluationConfig.relation_stamp_tolerance_s must lie in [0, 1] s");
  }
  if (!(config.min_matched_relations >= 0.0 && config.min_matched_relations <= 1.0)) {
    throw std::invalid_argument("EvaluationConfig.min_matched_relations must lie in [0, 1]");
  }
  if (config.truth_max_gap_scans < 0) {
    throw std::invalid_argument("EvaluationConfig.truth_max_gap_scans must be >= 0");
  }
  if (!(config.grid_tolerance_m >= 0.0 && config.grid_tolerance_m <= 10.0)) {
    throw std::invalid_argument("EvaluationConfig.grid_tolerance_m must be in [0, 10] m");
  }
  if (!(config.give_up_m > 0.0) || !(config.follow_m >= 0.0)) {
    throw std::invalid_argument(
        "EvaluationConfig.give_up_m must be positive and EvaluationConfig.follow_m >= 0");
  }
  if (!(config.revisit_room_m >= 0.0)) {
    throw std::invalid_argument("EvaluationConfig.revisit_room_m must be >= 0");
  }
  if (!(config.revisit_radius_m >= 0.0)) {
    throw std::invalid_argument("EvaluationConfig.revisit_radius_m must be >= 0");
  }
  if (!(config.revisit_angle_deg >= 0.0 && config.revisit_angle_deg <= 180.0)) {
    throw std::invalid_argument("EvaluationConfig.revisit_angle_deg must be in [0, 180]");
  }
}

}  // namespace keyplace
