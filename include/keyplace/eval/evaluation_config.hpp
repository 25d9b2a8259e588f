#pragma once
// Settings of the evaluations (not of the method): how relations are split, how far ground
// truth is carried to scans without a corrected pose, and which queries the map can answer.

namespace keyplace {

struct EvaluationConfig {
  // Relations with |t_b - t_a| below this are local, the others loop (Kümmerle et al.).
  double local_relation_max_dt_s = 5.0;
  // A relation stamp matches the scan with the nearest stamp within this (s): 0.1 ms, far below
  // a scan period (13-200 ms in the data sets) and far above the rounding of stamps written with
  // 5 or 6 decimals.
  double relation_stamp_tolerance_s = 1e-4;
  // No relation error is printed when fewer than this fraction of the relations inside the log's
  // time span matched (the reason is printed instead; JSON: null errors and "refusal").
  double min_matched_relations = 0.95;
  // A loop of `keyplace slam` is checked against ground truth when its submap origins lie at most
  // this many scans (processing order) from a scan with a corrected pose; FR101 has one corrected
  // scan per 16 raw ones.
  int truth_max_gap_scans = 50;
  // A query of `keyplace localize` is revisitable when its true pose has a map scan (of a place
  // the self-match rule leaves in) within this distance and this heading difference: the map
  // has seen the place, so a query without a correct answer there is a miss.
  double revisit_radius_m = 1.5;
  double revisit_angle_deg = 45.0;
  // keyplace relocalize: a start without a fix is given up after this odometry distance, and
  // after its first fix the fixes are checked over this further distance.
  double give_up_m = 50.0;
  double follow_m = 20.0;
  // keyplace relocalize: a start with a revisit has room when the path it has left after the
  // first scan the map has seen (before give_up_m or the log's end) is at least this long. Its
  // fixed fraction is reported beside the plain one: a start that meets the map a few metres
  // before it stops has no fair chance. 10 m is the path a fix of weak answers alone needs
  // (FixPolicy::weak_fix_span_m, a separate setting: change both together).
  double revisit_room_m = 10.0;
  // keyplace slam --grid with --truth: an occupied cell agrees with the reference grid when an
  // occupied reference cell lies within this (two cells of the default grid).
  double grid_tolerance_m = 0.1;
};

/// Throws std::invalid_argument naming the first invalid field.
void Validate(const EvaluationConfig& config);

}  // namespace keyplace
