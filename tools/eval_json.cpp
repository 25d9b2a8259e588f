#include "eval_json.hpp"

#include <string>
#include <utility>

namespace keyplace::cli {

nlohmann::json StatsJson(const ErrorStats& s) {
  return {{"count", s.count},
          {"translation_mean_m", s.translation_mean_m},
          {"translation_std_m", s.translation_std_m},
          {"translation_max_m", s.translation_max_m},
          {"rotation_mean_deg", s.rotation_mean_deg},
          {"rotation_std_deg", s.rotation_std_deg},
          {"rotation_max_deg", s.rotation_max_deg}};
}

namespace {

// One split's flat keys for scripts (prefix "" for all relations) and its full statistics under
// `name`; all null when the split has no error to give.
void AddSplit(const std::string& prefix, const char* name, const ErrorStats& s, bool known,
              nlohmann::json& json) {
  const std::pair<const char*, double> flat[] = {{"translation_mean_m", s.translation_mean_m},
                                                 {"translation_std_m", s.translation_std_m},
                                                 {"rotation_mean_deg", s.rotation_mean_deg},
                                                 {"rotation_std_deg", s.rotation_std_deg}};
  for (const auto& [key, value] : flat) {
    json[prefix + key] = known ? nlohmann::json(value) : nlohmann::json(nullptr);
  }
  json[name] = known ? StatsJson(s) : nlohmann::json(nullptr);
}

}  // namespace

nlohmann::json RelationJson(const RelationErrorReport& r) {
  nlohmann::json json;
  json["relations"] = r.relations;
  json["matched"] = r.matched;
  json["unmatched"] = r.unmatched;
  json["outside_span"] = r.outside_span;
  json["duplicate_timestamps"] = r.duplicate_timestamps;
  // Refused: no error figures at all, so no script can read one by mistake. A split without
  // relations has no error, not an error of 0.
  const bool given = r.refusal.empty();
  json["refusal"] = given ? nlohmann::json(nullptr) : nlohmann::json(r.refusal);
  AddSplit("", "all", r.all, given, json);
  AddSplit("local_", "local", r.local, given && r.local.count > 0, json);
  AddSplit("loop_", "loop", r.loop, given && r.loop.count > 0, json);
  return json;
}

std::string OutsideSpanNote(const RelationErrorReport& report) {
  if (report.outside_span == 0) return "";
  return ", " + std::to_string(report.outside_span) + " outside the log's time span";
}

}  // namespace keyplace::cli
