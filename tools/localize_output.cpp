#include "localize_output.hpp"

#include <cmath>
#include <filesystem>

#include <fmt/core.h>
#include <fmt/ostream.h>

#include "io/atomic_file.hpp"
#include "paper_tables.hpp"
#include "result_json.hpp"

namespace keyplace::cli {
namespace {

nlohmann::json ReliabilityJson(const std::vector<ReliabilityBin>& bins) {
  nlohmann::json json = nlohmann::json::array();
  for (const ReliabilityBin& b : bins) {
    json.push_back({{"bin_low", b.bin_low},
                    {"bin_high", b.bin_high},
                    {"count", b.count},
                    {"confidence_mean", b.confidence_mean},
                    {"precision", b.precision}});
  }
  return json;
}

std::string SelfMatchName(SelfMatchRule rule) {
  switch (rule) {
    case SelfMatchRule::kNone:
      return "none";
    case SelfMatchRule::kSameScans:
      return "same_scans";
    case SelfMatchRule::kSharedScan:
      return "shared_scan";
  }
  return "?";
}

nlohmann::json CurveJson(const std::vector<PrPoint>& curve) {
  nlohmann::json points = nlohmann::json::array();
  for (const PrPoint& p : curve) {
    points.push_back({{"threshold", p.threshold},
                      {"accepted", p.accepted},
                      {"correct", p.correct},
                      {"precision", p.precision},
                      {"recall", p.recall}});
  }
  return points;
}

std::string DatasetOf(const std::string& log_path) {
  const auto dataset = DatasetName(log_path);
  return dataset ? *dataset : "";
}

const PaperLocalizationRow* PaperRow(const LocalizeReport& r) {
  const bool paper_setting =
      !r.baseline && r.place.min_pairs == 10 && std::abs(r.place.min_gamma - 0.4) < 1e-9;
  return paper_setting ? PaperLocalization(DatasetOf(r.log_path), r.place.double_match_m) : nullptr;
}

const PaperPglPcl* PaperX(const LocalizeReport& r) {
  return PaperTableX(DatasetOf(r.log_path), r.baseline ? "tip-flirt" : "ours", r.place.min_pairs,
                     r.place.double_match_m);
}

}  // namespace

void WarnAboutMapSource(const std::string& map_path, const GlobalMap& map,
                        const std::string& truth_log_path, bool truth_is_map_log) {
  if (map.pose_source != "corrected") {
    fmt::print(stderr,
               "keyplace: warning: {} was built from {} poses; the truth is in the corrected "
               "frame\n",
               map_path, map.pose_source);
  }
  // Another file name is a deliberate choice (protocol (d)), which localize reports on stdout;
  // the same name with other contents is more likely a mistake.
  const std::string expected = std::filesystem::path(truth_log_path).filename().string();
  if (map.source_log == expected && !truth_is_map_log) {
    fmt::print(stderr,
               "keyplace: warning: {} was built from a file named {} with other contents ({}) "
               "than {}: the queries count as another recording\n",
               map_path, map.source_log, map.source_hash, truth_log_path);
  }
}

void PrintLocalizeReport(const LocalizeReport& r) {
  const LocalizationSummary& s = r.summary;
  const std::string dataset = DatasetOf(r.log_path);
  const std::string scans = r.first_scan == 0 && r.log_scans == r.file_scans
                                ? fmt::format("{} scans", r.log_scans)
                                : fmt::format("scans {}:{} of {}", r.first_scan,
                                              r.first_scan + r.log_scans, r.file_scans);
  fmt::print("log                {} ({}, {} poses), {} queries of {} requested\n", r.log_path,
             scans, ToString(r.pose_source), s.n_pos, r.n_requested);
  fmt::print("map                {}\n", r.map_description);
  // Single-scan baseline queries carry no all-scan keypoints, so min_gamma applies to them.
  const bool all_scan_queries =
      !r.baseline && r.place.query_keypoints == PlaceRecognitionConfig::QueryKeypoints::kAllScans;
  fmt::print("config             preset {}, mu {}, gamma_min {}, lambda {} m, self-match {}\n",
             r.preset, r.place.min_pairs,
             all_scan_queries
                 ? fmt::format("{} (all-scan query keypoints)", r.place.min_gamma_all_scans)
                 : fmt::format("{}", r.place.min_gamma),
             r.place.double_match_m,
             r.self_match == SelfMatchRule::kNone
                 ? "none"
                 : (r.exclude_shared_scans ? "shared-scan" : "same-scans"));
  fmt::print("accepted           {} (verified {}, ambiguous {} of which {} wrong)\n", s.n_acc,
             s.n_verified, s.n_ambiguous, s.n_ambiguous_wrong);
  fmt::print("correct            {}\n", s.n_cor);
  fmt::print(
      "revisitable        {} (a map scan within {} m, {} deg of the true pose), recall {:.3f}\n",
      s.n_revisitable, r.evaluation.revisit_radius_m, r.evaluation.revisit_angle_deg,
      s.recall_revisitable);
  fmt::print("P_GL / P_CL        {:.3f} / {:.3f} (ranked by {})\n", s.p_gl, s.p_cl,
             ToString(s.rank_by));
  fmt::print(
      "time               {:.4f} s per query recognition, {:.4f} s submap building; "
      "preparation (poses, keypoints) {:.1f} s{}\n",
      s.seconds_per_query_mean, s.seconds_submap_building_mean, r.preparation_seconds,
      r.preparation_from_cache ? " (from the cache)" : "");
  fmt::print("\n{:<18} {:>9} {:>7} {:>7} {:>9}\n", dataset, "Precision", "Recall", "#Scans",
             "Time (s)");
  if (const PaperLocalizationRow* paper = PaperRow(r)) {
    fmt::print("  {:<18}{:9.2f} {:7.2f} {:7.2f} {:9.3f}\n",
               fmt::format("paper (Tab. {})", paper->table), paper->precision, paper->recall,
               paper->scans, paper->seconds);
  }
  fmt::print("  keyplace         {:9.3f} {:7.3f} {:7.2f} {:9.4f}\n", s.precision, s.recall,
             s.scans_mean, s.seconds_per_query_mean);
  if (const PaperPglPcl* paper_x = PaperX(r)) {
    fmt::print("\nTable X {:<10} {:>6} {:>6}\n", r.baseline ? "TIP-FLIRT" : "", "P_GL", "P_CL");
    fmt::print("  paper            {:6.2f} {:6.2f}\n", paper_x->p_gl, paper_x->p_cl);
    fmt::print("  keyplace         {:6.2f} {:6.2f}\n", s.p_gl, s.p_cl);
  }
}

void WriteQueriesTsv(const std::string& path, const std::vector<LocalizationRecord>& records,
                     std::size_t first_scan) {
  WriteFileAtomically(path, [&](std::ostream& out) {
    out << "start_scan\tevaluated_scan\tscans\tverified\taccepted\tambiguous\tcorrect\t"
           "matched_submap\test_x\test_y\test_theta\ttrue_x\ttrue_y\ttrue_theta\tconsensus\t"
           "gamma\tscore\tsecond_score\tconfidence\tcandidates\tseconds\treference_coverage\t"
           "places_excluded\trevisitable\tdense_endpoints\tdense_hit_fraction\tdense_see_through\n";
    for (const LocalizationRecord& r : records) {
      const PlaceMatch& m = r.match;
      fmt::print(out,
                 "{}\t{}\t{}\t{:d}\t{:d}\t{:d}\t{:d}\t{}\t{:.4f}\t{:.4f}\t{:.5f}\t{:.4f}\t"
                 "{:.4f}\t{:.5f}\t{}\t{:.4f}\t{:.4f}\t{:.4f}\t{:.4f}\t{}\t{:.6f}\t{:.4f}\t{}\t{:d}"
                 "\t{}\t{:.4f}\t{:.4f}\n",
                 first_scan + static_cast<std::size_t>(r.start_scan),
                 first_scan + static_cast<std::size_t>(r.evaluated_scan), r.scans, m.verified,
                 m.found, m.ambiguous, r.correct, m.place_id, m.estimated_pose.x,
                 m.estimated_pose.y, m.estimated_pose.theta, r.truth.x, r.truth.y, r.truth.theta,
                 m.consensus, m.gamma, m.score, m.second_score, m.confidence, m.candidates,
                 m.seconds, m.reference_coverage, m.places_excluded, r.revisitable,
                 m.dense.endpoints, m.dense.hit_fraction, m.dense.see_through_fraction);
    }
  });
}

void WriteCurveTsv(const std::string& path, const std::vector<PrPoint>& curve) {
  WriteFileAtomically(path, [&](std::ostream& out) {
    out << "threshold\taccepted\tcorrect\tprecision\trecall\n";
    for (const PrPoint& p : curve) {
      fmt::print(out, "{:.6f}\t{}\t{}\t{:.6f}\t{:.6f}\n", p.threshold, p.accepted, p.correct,
                 p.precision, p.recall);
    }
  });
}

void WriteReliabilityTsv(const std::string& path, const std::vector<ReliabilityBin>& bins) {
  WriteFileAtomically(path, [&](std::ostream& out) {
    out << "bin_low\tbin_high\tcount\tconfidence_mean\tprecision\n";
    for (const ReliabilityBin& b : bins) {
      fmt::print(out, "{:.2f}\t{:.2f}\t{}\t{:.6f}\t{:.6f}\n", b.bin_low, b.bin_high, b.count,
                 b.confidence_mean, b.precision);
    }
  });
}

nlohmann::json LocalizeJson(const LocalizeReport& r,
                            const std::vector<LocalizationRecord>& records) {
  const LocalizationSummary& s = r.summary;
  nlohmann::json json;
  json["log"] = r.log_path;
  json["dataset"] = DatasetOf(r.log_path);
  json["pose_source"] = ToString(r.pose_source);
  json["preset"] = r.preset;
  json["self_match"] = SelfMatchName(r.self_match);
  json["truth_is_map_log"] = r.truth_is_map_log;
  json["first_scan"] = r.first_scan;
  json["scans"] = r.log_scans;
  json["skipped_lines"] = r.skipped_lines;
  json["n_pos_requested"] = r.n_requested;
  json["revisit_radius_m"] = r.evaluation.revisit_radius_m;
  json["revisit_angle_deg"] = r.evaluation.revisit_angle_deg;
  json["seconds_preparation"] = r.preparation_seconds;
  json["preparation_from_cache"] = r.preparation_from_cache;
  AddResultFields(s, LocalizationSummaryFields(), json);
  json["curve"] = CurveJson(s.curve);
  json["reliability"] = ReliabilityJson(s.reliability);
  nlohmann::json others;
  for (const RankBy key :
       {RankBy::kGamma, RankBy::kConfidence, RankBy::kConsensus, RankBy::kScore}) {
    const LocalizationSummary ranked = Summarize(records, key);
    others[ToString(key)] = {{"p_gl", ranked.p_gl}, {"p_cl", ranked.p_cl}};
  }
  json["p_gl_p_cl_by_rank"] = others;
  if (const PaperLocalizationRow* paper = PaperRow(r)) {
    json["paper"] = {{"table", paper->table},
                     {"precision", paper->precision},
                     {"recall", paper->recall},
                     {"scans_mean", paper->scans},
                     {"seconds_per_query_mean", paper->seconds}};
  }
  if (const PaperPglPcl* paper_x = PaperX(r)) {
    json["paper_table_x"] = {{"p_gl", paper_x->p_gl}, {"p_cl", paper_x->p_cl}};
  }
  return json;
}

}  // namespace keyplace::cli
