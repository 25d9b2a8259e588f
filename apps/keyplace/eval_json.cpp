#include "eval_json.hpp"

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

nlohmann::json RelationJson(const RelationErrorReport& r) {
  nlohmann::json json;
  json["relations"] = r.relations;
  json["matched"] = r.matched;
  json["unmatched"] = r.unmatched;
  json["outside_span"] = r.outside_span;
  json["duplicate_timestamps"] = r.duplicate_timestamps;
  if (!r.refusal.empty()) {  // no error figures at all, so no script can read one by mistake
    json["refusal"] = r.refusal;
    for (const char* key :
         {"translation_mean_m", "translation_std_m", "rotation_mean_deg", "rotation_std_deg",
          "local_translation_mean_m", "local_translation_std_m", "local_rotation_mean_deg",
          "local_rotation_std_deg", "loop_translation_mean_m", "loop_translation_std_m",
          "loop_rotation_mean_deg", "loop_rotation_std_deg", "all", "local", "loop"}) {
      json[key] = nullptr;
    }
    return json;
  }
  json["refusal"] = nullptr;
  // Flat keys for scripts, then the full statistics per split.
  json["translation_mean_m"] = r.all.translation_mean_m;
  json["translation_std_m"] = r.all.translation_std_m;
  json["rotation_mean_deg"] = r.all.rotation_mean_deg;
  json["rotation_std_deg"] = r.all.rotation_std_deg;
  json["local_translation_mean_m"] = r.local.translation_mean_m;
  json["local_translation_std_m"] = r.local.translation_std_m;
  json["local_rotation_mean_deg"] = r.local.rotation_mean_deg;
  json["local_rotation_std_deg"] = r.local.rotation_std_deg;
  json["loop_translation_mean_m"] = r.loop.translation_mean_m;
  json["loop_translation_std_m"] = r.loop.translation_std_m;
  json["loop_rotation_mean_deg"] = r.loop.rotation_mean_deg;
  json["loop_rotation_std_deg"] = r.loop.rotation_std_deg;
  json["all"] = StatsJson(r.all);
  json["local"] = StatsJson(r.local);
  json["loop"] = StatsJson(r.loop);
  // A split without relations has no error, not an error of 0.
  for (const char* split : {"local", "loop"}) {
    if (json[split]["count"] != 0) continue;
    for (const char* stat :
         {"translation_mean_m", "translation_std_m", "rotation_mean_deg", "rotation_std_deg"}) {
      json[std::string(split) + "_" + stat] = nullptr;
    }
    json[split] = nullptr;
  }
  return json;
}

std::string OutsideSpanNote(const RelationErrorReport& report) {
  if (report.outside_span == 0) return "";
  return ", " + std::to_string(report.outside_span) + " outside the log's time span";
}

}  // namespace keyplace::cli
