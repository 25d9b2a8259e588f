// keyplace localize: global localization against a map (paper Algorithm 4, Sections 5.2, 6.2.1
// and 6.3): n_pos query submaps from equally spaced starts, place recognition, precision/recall,
// the precision-recall curve with P_GL / P_CL, and the TIP-FLIRT single-scan baseline.

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <memory>
#include <numeric>
#include <optional>
#include <string>
#include <vector>

#include <fmt/core.h>
#include <fmt/ostream.h>
#include <nlohmann/json.hpp>

#include "cli_support.hpp"
#include "commands.hpp"
#include "config_options.hpp"
#include "keyplace/eval/localization.hpp"
#include "keyplace/io/atomic_file.hpp"
#include "keyplace/io/carmen_log.hpp"
#include "keyplace/io/relations.hpp"
#include "keyplace/mapping/global_mapper.hpp"
#include "keyplace/mapping/scan_sources.hpp"
#include "keyplace/place/place_recognizer.hpp"
#include "keyplace/place/submap_query.hpp"
#include "keyplace/store/map_file.hpp"
#include "paper_tables.hpp"

namespace keyplace::cli {
namespace {

using Clock = std::chrono::steady_clock;

double Seconds(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

struct LocalizeOptions {
  std::string map_path;
  std::string log_path;
  std::string poses = "corrected";
  std::string truth_path;
  std::string index_path;
  std::string json_path;
  std::string queries_path;
  std::string curve_path;
  std::string preset = "default";
  std::string baseline;
  std::string rank_by;
  std::vector<std::string> assignments;
  std::optional<int> mu;
  std::optional<double> gamma_min;
  std::optional<double> lambda;
  std::optional<double> min_confidence;
  int n_pos = 500;
  bool exclude_shared_scans = false;
};

// One evaluated query.
struct QueryRecord {
  int start_scan = 0;
  int evaluated_scan = 0;
  int scans = 0;  // scans in the query (1 for the baseline)
  PlaceMatch match;
  Pose2 truth;
  bool correct = false;           // accepted and within 0.5 m / 10 deg
  bool verified_correct = false;  // best verified candidate within 0.5 m / 10 deg
  double build_seconds = 0.0;
};

double RankScore(const std::string& rank_by, const PlaceMatch& match) {
  if (rank_by == "gamma") return match.gamma;
  if (rank_by == "consensus") return match.consensus;
  if (rank_by == "score") return match.score;
  return match.confidence;
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

void RunLocalize(const LocalizeOptions& options) {
  const auto start = Clock::now();
  const bool baseline = !options.baseline.empty();
  if (baseline && options.baseline != "tip-flirt") {
    throw std::invalid_argument("--baseline '" + options.baseline + "': expected tip-flirt");
  }
  if (!baseline && options.map_path.empty()) {
    throw std::invalid_argument("--map is required (except with --baseline tip-flirt)");
  }
  if (options.n_pos < 1) throw std::invalid_argument("--n-pos must be >= 1");

  PlaceRecognitionConfig config = PlacePreset(options.preset);
  if (options.mu) config.min_pairs = *options.mu;
  if (options.gamma_min) {  // for stable and all-scan query keypoints alike
    config.min_gamma = *options.gamma_min;
    config.min_gamma_all_scans = *options.gamma_min;
  } else if (baseline) {
    // Tipaldi's protocol accepts on the RANSAC consensus alone; a gamma check between two single
    // scans at lambda = 0.05 m rejects most true neighbours (docs/PLACE.md, "TIP-FLIRT").
    config.min_gamma = 0.0;
    config.min_gamma_all_scans = 0.0;
  }
  if (options.lambda) config.double_match_m = *options.lambda;
  if (options.min_confidence) config.min_confidence = *options.min_confidence;
  ApplyKeyValues(ParseAssignments(options.assignments), config);
  std::string rank_by = options.rank_by;
  if (rank_by.empty()) {
    rank_by = baseline ? "consensus" : (options.preset == "paper" ? "gamma" : "confidence");
  }
  const SelfMatchRule rule =
      options.exclude_shared_scans ? SelfMatchRule::kSharedScan : SelfMatchRule::kSameScans;

  // --- the query log, its poses and keypoints
  const CarmenLog log = ReadLogWithScans(options.log_path);
  const PoseSource source = ParsePoseSource(options.poses);
  if (source == PoseSource::kCorrected && !log.corrected) {
    throw std::invalid_argument(options.log_path +
                                ": --poses corrected needs a corrected log (VERTEX2/NEFF lines)");
  }
  const bool own_truth = options.truth_path.empty();
  if (own_truth != options.index_path.empty()) {
    throw std::invalid_argument("--truth and --index must be given together");
  }
  if (own_truth && !log.corrected) {
    throw std::invalid_argument(options.log_path +
                                " has no corrected poses: give --truth CORRECTED_LOG and --index "
                                "RAW_TO_CORRECTED.tsv");
  }
  std::optional<CarmenLog> truth_log;
  std::vector<int> corrected_of(log.scans.size(), -1);  // query scan -> truth scan
  if (own_truth) {
    std::iota(corrected_of.begin(), corrected_of.end(), 0);
  } else {
    truth_log = ReadLogWithScans(options.truth_path);
    if (!truth_log->corrected) {
      throw std::invalid_argument(options.truth_path + ": --truth must be a corrected log");
    }
    for (const IndexPair& pair : ReadIndexPairs(options.index_path)) {
      if (pair.raw_index >= log.scans.size() || pair.corrected_index >= truth_log->scans.size()) {
        throw std::invalid_argument(
            fmt::format("{}: pair {} -> {} lies outside {} ({} scans) or {} ({} scans)",
                        options.index_path, pair.raw_index, pair.corrected_index, options.log_path,
                        log.scans.size(), options.truth_path, truth_log->scans.size()));
      }
      corrected_of[pair.raw_index] = static_cast<int>(pair.corrected_index);
    }
  }
  const CarmenLog& map_log = own_truth ? log : *truth_log;
  const std::string& map_log_path = own_truth ? options.log_path : options.truth_path;
  auto truth_pose = [&](int query_scan) {
    return *map_log.scans[corrected_of[query_scan]].corrected_pose;
  };

  Progress pose_progress("poses (" + ToString(source) + ")", log.scans.size());
  const std::vector<Pose2> poses = ScanPoses(
      log, source, {}, [&](std::size_t done, std::size_t) { pose_progress.Update(done); });
  pose_progress.Finish();
  const FlirtExtractor extractor;
  Progress keypoint_progress("keypoints", log.scans.size());
  const std::vector<std::vector<Keypoint>> keypoints = ExtractKeypoints(
      log, extractor, [&](std::size_t done, std::size_t) { keypoint_progress.Update(done); });
  keypoint_progress.Finish();
  const double preparation_seconds = Seconds(start);

  // --- the places
  std::vector<Place> places;
  MappingConfig mapping_config;
  std::string map_description;
  if (!baseline) {
    const GlobalMap map = LoadMap(options.map_path);
    if (map.pose_source != "corrected") {
      fmt::print(stderr,
                 "keyplace: warning: {} was built from {} poses; the truth is in the corrected "
                 "frame\n",
                 options.map_path, map.pose_source);
    }
    const std::string expected = std::filesystem::path(map_log_path).filename().string();
    if (map.source_log != expected) {
      fmt::print(stderr, "keyplace: warning: {} was built from {}, the truth comes from {}\n",
                 options.map_path, map.source_log, expected);
    }
    mapping_config = map.config;
    places = PlacesFromMap(map);
    map_description = fmt::format("{} ({} submaps, {} keypoints)", options.map_path,
                                  map.submaps.size(), map.KeypointCount());
  } else {
    // TIP-FLIRT: every scan of the corrected log is a place with all its FLIRT keypoints.
    const std::vector<std::vector<Keypoint>> map_keypoints =
        own_truth ? keypoints : ExtractKeypoints(map_log, extractor);
    std::size_t total = 0;
    for (std::size_t k = 0; k < map_log.scans.size(); ++k) {
      Place place;
      place.id = static_cast<int>(k);
      place.T_world_place = *map_log.scans[k].corrected_pose;
      for (const Keypoint& keypoint : map_keypoints[k]) {
        place.positions.push_back(map_log.scans[k].T_robot_laser * keypoint.position_m);
        place.descriptors.push_back(keypoint.descriptor);
      }
      place.scan_indices = {static_cast<int>(k)};
      total += place.positions.size();
      places.push_back(std::move(place));
    }
    map_description = fmt::format("TIP-FLIRT: {} scans of {} as places ({} keypoints)",
                                  places.size(), map_log_path, total);
  }
  const PlaceRecognizer recognizer(std::move(places), config);

  // --- Algorithm 4
  std::vector<int> eligible;  // query scans with a truth pose
  for (std::size_t k = 0; k < log.scans.size(); ++k) {
    if (corrected_of[k] >= 0) eligible.push_back(static_cast<int>(k));
  }
  if (eligible.empty()) throw std::invalid_argument("no query scan has a ground-truth pose");
  const int n_requested = options.n_pos;
  const ScanSequence sequence{log.scans, poses, keypoints};
  LocalMapper mapper(mapping_config);
  std::vector<QueryRecord> records;
  Progress progress("localize", static_cast<std::size_t>(n_requested));
  for (int i = 0; i < n_requested; ++i) {
    const std::size_t pick = static_cast<std::size_t>(i) * eligible.size() / n_requested;
    const int start_scan = eligible[pick];
    QueryRecord record;
    record.start_scan = start_scan;
    PlaceQuery query;
    std::vector<int> query_truth_scans;
    if (!baseline) {
      const auto build_start = Clock::now();
      const std::optional<Submap> submap = BuildSubmap(sequence, start_scan, mapper);
      record.build_seconds = Seconds(build_start);
      if (!submap) break;  // Algorithm 4: the log ends before the submap is complete
      int evaluated = -1;
      for (auto it = submap->scan_indices.rbegin(); it != submap->scan_indices.rend(); ++it) {
        if (corrected_of[*it] >= 0) {
          evaluated = *it;
          break;
        }
      }
      record.evaluated_scan = evaluated;  // >= 0: the start scan has a truth pose
      record.scans = static_cast<int>(submap->scan_indices.size());
      query = MakeSubmapQuery(*submap, sequence, evaluated, config.query_keypoints);
      for (int scan : submap->scan_indices) {
        if (corrected_of[scan] >= 0) query_truth_scans.push_back(corrected_of[scan]);
      }
    } else {
      record.evaluated_scan = start_scan;
      record.scans = 1;
      const LaserScan& scan = log.scans[start_scan];
      for (const Keypoint& keypoint : keypoints[start_scan]) {
        query.positions.push_back(scan.T_robot_laser * keypoint.position_m);
        query.descriptors.push_back(keypoint.descriptor);
      }
      query_truth_scans = {corrected_of[start_scan]};
    }
    record.truth = truth_pose(record.evaluated_scan);
    std::sort(query_truth_scans.begin(), query_truth_scans.end());
    record.match = recognizer.Recognize(query, [&](const Place& place) {
      return IsSelfMatch(rule, query_truth_scans, place.scan_indices);
    });
    record.verified_correct =
        record.match.verified && IsCorrectPose(record.match.estimated_pose, record.truth);
    record.correct = record.match.found && record.verified_correct;
    records.push_back(std::move(record));
    progress.Update(static_cast<std::size_t>(i) + 1);
  }
  progress.Finish();

  // --- figures
  const std::size_t n_pos = records.size();
  std::size_t n_acc = 0;
  std::size_t n_cor = 0;
  std::size_t n_verified = 0;
  std::size_t n_ambiguous = 0;
  std::size_t n_ambiguous_wrong = 0;
  double scans_correct = 0.0;
  double seconds = 0.0;
  double build_seconds = 0.0;
  double scans_all = 0.0;
  for (const QueryRecord& r : records) {
    seconds += r.match.seconds;
    build_seconds += r.build_seconds;
    scans_all += r.scans;
    if (r.match.verified) ++n_verified;
    if (r.match.ambiguous) {
      ++n_ambiguous;
      if (!r.verified_correct) ++n_ambiguous_wrong;
    }
    if (r.match.found) ++n_acc;
    if (r.correct) {
      ++n_cor;
      scans_correct += r.scans;
    }
  }
  const double precision = n_acc > 0 ? static_cast<double>(n_cor) / n_acc : 0.0;
  const double recall = n_pos > 0 ? static_cast<double>(n_cor) / n_pos : 0.0;
  const double scans_mean = n_cor > 0 ? scans_correct / n_cor : 0.0;
  const double seconds_mean = n_pos > 0 ? seconds / n_pos : 0.0;
  const double build_seconds_mean = n_pos > 0 ? build_seconds / n_pos : 0.0;

  auto curve_for = [&](const std::string& key) {
    std::vector<RankedAnswer> answers;
    answers.reserve(records.size());
    for (const QueryRecord& r : records) {
      answers.push_back({r.match.verified, r.verified_correct, RankScore(key, r.match)});
    }
    return PrecisionRecallCurve(answers, n_pos);
  };
  const std::vector<PrPoint> curve = curve_for(rank_by);
  const double p_gl = PrecisionAtMaxRecall(curve);
  const double p_cl = RecallAtPrecision(curve, 0.95);

  const auto dataset = DatasetName(options.log_path);
  const std::string dataset_name = dataset ? *dataset : "";
  const PaperLocalizationRow* paper =
      !baseline && config.min_pairs == 10 && std::abs(config.min_gamma - 0.4) < 1e-9
          ? PaperLocalization(dataset_name, config.double_match_m)
          : nullptr;
  const PaperPglPcl* paper_x = PaperTableX(dataset_name, baseline ? "tip-flirt" : "ours",
                                           config.min_pairs, config.double_match_m);

  fmt::print("log                {} ({} scans, {} poses), {} queries of {} requested\n",
             options.log_path, log.scans.size(), ToString(source), n_pos, n_requested);
  fmt::print("map                {}\n", map_description);
  // Single-scan baseline queries carry no all-scan keypoints, so min_gamma applies to them.
  const bool all_scan_queries =
      !baseline && config.query_keypoints == PlaceRecognitionConfig::QueryKeypoints::kAllScans;
  fmt::print("config             preset {}, mu {}, gamma_min {}, lambda {} m, self-match {}\n",
             options.preset, config.min_pairs,
             all_scan_queries
                 ? fmt::format("{} (all-scan query keypoints)", config.min_gamma_all_scans)
                 : fmt::format("{}", config.min_gamma),
             config.double_match_m, options.exclude_shared_scans ? "shared-scan" : "same-scans");
  fmt::print("accepted           {} (verified {}, ambiguous {} of which {} wrong)\n", n_acc,
             n_verified, n_ambiguous, n_ambiguous_wrong);
  fmt::print("correct            {}\n", n_cor);
  fmt::print("P_GL / P_CL        {:.3f} / {:.3f} (ranked by {})\n", p_gl, p_cl, rank_by);
  fmt::print(
      "time               {:.4f} s per query recognition, {:.4f} s submap building; "
      "preparation (poses, keypoints) {:.1f} s\n",
      seconds_mean, build_seconds_mean, preparation_seconds);
  fmt::print("\n{:<18} {:>9} {:>7} {:>7} {:>9}\n", dataset_name.empty() ? "" : dataset_name,
             "Precision", "Recall", "#Scans", "Time (s)");
  if (paper) {
    fmt::print("  {:<18}{:9.2f} {:7.2f} {:7.2f} {:9.3f}\n",
               fmt::format("paper (Tab. {})", paper->table), paper->precision, paper->recall,
               paper->scans, paper->seconds);
  }
  fmt::print("  keyplace         {:9.3f} {:7.3f} {:7.2f} {:9.4f}\n", precision, recall, scans_mean,
             seconds_mean);
  if (paper_x) {
    fmt::print("\nTable X {:<10} {:>6} {:>6}\n", baseline ? "TIP-FLIRT" : "", "P_GL", "P_CL");
    fmt::print("  paper            {:6.2f} {:6.2f}\n", paper_x->p_gl, paper_x->p_cl);
    fmt::print("  keyplace         {:6.2f} {:6.2f}\n", p_gl, p_cl);
  }

  if (!options.queries_path.empty()) {
    WriteFileAtomically(options.queries_path, [&](std::ostream& out) {
      out << "start_scan\tevaluated_scan\tscans\tverified\taccepted\tambiguous\tcorrect\t"
             "matched_submap\test_x\test_y\test_theta\ttrue_x\ttrue_y\ttrue_theta\tconsensus\t"
             "gamma\tscore\tsecond_score\tconfidence\tcandidates\tseconds\treference_coverage\n";
      for (const QueryRecord& r : records) {
        const PlaceMatch& m = r.match;
        fmt::print(out,
                   "{}\t{}\t{}\t{:d}\t{:d}\t{:d}\t{:d}\t{}\t{:.4f}\t{:.4f}\t{:.5f}\t{:.4f}\t"
                   "{:.4f}\t{:.5f}\t{}\t{:.4f}\t{:.4f}\t{:.4f}\t{:.4f}\t{}\t{:.6f}\t{:.4f}\n",
                   r.start_scan, r.evaluated_scan, r.scans, m.verified, m.found, m.ambiguous,
                   r.correct, m.place_id, m.estimated_pose.x, m.estimated_pose.y,
                   m.estimated_pose.theta, r.truth.x, r.truth.y, r.truth.theta, m.consensus,
                   m.gamma, m.score, m.second_score, m.confidence, m.candidates, m.seconds,
                   m.reference_coverage);
      }
    });
  }
  if (!options.curve_path.empty()) {
    WriteFileAtomically(options.curve_path, [&](std::ostream& out) {
      out << "threshold\taccepted\tcorrect\tprecision\trecall\n";
      for (const PrPoint& p : curve) {
        fmt::print(out, "{:.6f}\t{}\t{}\t{:.6f}\t{:.6f}\n", p.threshold, p.accepted, p.correct,
                   p.precision, p.recall);
      }
    });
  }
  if (!options.json_path.empty()) {
    nlohmann::json json;
    json["log"] = options.log_path;
    json["dataset"] = dataset_name;
    json["map"] = baseline ? "" : options.map_path;
    json["baseline"] = options.baseline;
    json["truth"] = options.truth_path;
    json["pose_source"] = ToString(source);
    json["preset"] = options.preset;
    json["self_match"] = options.exclude_shared_scans ? "shared_scan" : "same_scans";
    json["places"] = recognizer.places().size();
    json["n_pos_requested"] = n_requested;
    json["n_pos"] = n_pos;
    json["n_acc"] = n_acc;
    json["n_cor"] = n_cor;
    json["n_verified"] = n_verified;
    json["n_ambiguous"] = n_ambiguous;
    json["precision"] = precision;
    json["recall"] = recall;
    json["scans_mean"] = scans_mean;
    json["scans_mean_all_queries"] = n_pos > 0 ? scans_all / n_pos : 0.0;
    json["seconds_per_query_mean"] = seconds_mean;
    json["seconds_submap_building_mean"] = build_seconds_mean;
    json["seconds_preparation"] = preparation_seconds;
    json["rank_by"] = rank_by;
    json["p_gl"] = p_gl;
    json["p_cl"] = p_cl;
    json["curve"] = CurveJson(curve);
    nlohmann::json others;
    for (const std::string key : {"gamma", "confidence", "consensus", "score"}) {
      const std::vector<PrPoint> c = curve_for(key);
      others[key] = {{"p_gl", PrecisionAtMaxRecall(c)}, {"p_cl", RecallAtPrecision(c, 0.95)}};
    }
    json["p_gl_p_cl_by_rank"] = others;
    nlohmann::json config_json;
    for (const auto& [key, value] : ToKeyValues(config)) config_json[key] = value;
    json["config"] = config_json;
    if (paper) {
      json["paper"] = {{"table", paper->table},
                       {"precision", paper->precision},
                       {"recall", paper->recall},
                       {"scans_mean", paper->scans},
                       {"seconds_per_query_mean", paper->seconds}};
    }
    if (paper_x) json["paper_table_x"] = {{"p_gl", paper_x->p_gl}, {"p_cl", paper_x->p_cl}};
    json["seconds_total"] = Seconds(start);
    WriteJson(options.json_path, json);
  }
}

}  // namespace

void RegisterLocalizeCommand(CLI::App& app) {
  auto options = std::make_shared<LocalizeOptions>();
  CLI::App* command = app.add_subcommand(
      "localize",
      "Global localization against a map (paper Algorithm 4): query submaps from n_pos equally "
      "spaced starts, place recognition, precision/recall, P_GL/P_CL, or the TIP-FLIRT "
      "single-scan baseline.");
  command->add_option("--map", options->map_path, "Map file (.kpm) built from the corrected log")
      ->check(CLI::ExistingFile);
  command->add_option("--log", options->log_path, "Query log (corrected or raw)")
      ->required()
      ->check(CLI::ExistingFile);
  command
      ->add_option("--poses", options->poses,
                   "Query poses: corrected (the log's), icp (scan matching on odometry) or "
                   "odometry")
      ->check(CLI::IsMember({"corrected", "icp", "odometry"}))
      ->capture_default_str();
  command
      ->add_option("--truth", options->truth_path,
                   "Corrected log giving the ground truth of a raw query log")
      ->check(CLI::ExistingFile);
  command
      ->add_option("--index", options->index_path,
                   "raw_index<TAB>corrected_index file relating --log to --truth")
      ->check(CLI::ExistingFile);
  command->add_option("--mu", options->mu, "Minimal unique descriptor pairs (default 10)");
  command->add_option(
      "--gamma-min", options->gamma_min,
      "gamma_min (default 0.4; sets min_gamma and min_gamma_all_scans, default 0.15; 0 with "
      "--baseline tip-flirt)");
  command->add_option("--lambda", options->lambda, "lambda in m (default 0.05)");
  command->add_option("--min-confidence", options->min_confidence,
                      "Accept only answers with at least this confidence (0..1)");
  command
      ->add_option("--preset", options->preset,
                   "default (all candidates verified, best score, ambiguity rejection), paper "
                   "(first verified candidate, FLIRTLib RANSAC) or strict (default plus the "
                   "reference-coverage check, for maps recorded on another day)")
      ->check(CLI::IsMember({"default", "paper", "strict"}))
      ->capture_default_str();
  command->add_option("--set", options->assignments,
                      "Override a PlaceRecognitionConfig field, KEY=VALUE (repeatable)");
  command->add_option("--n-pos", options->n_pos, "Number of queries")->capture_default_str();
  command->add_flag("--exclude-shared-scans", options->exclude_shared_scans,
                    "Skip every map submap sharing a scan with the query (default: only submaps "
                    "built from exactly the query's scans, the paper's rule)");
  command
      ->add_option("--baseline", options->baseline,
                   "tip-flirt: every scan of the corrected log is a place, each query one scan, "
                   "accepted on the RANSAC consensus (no gamma check unless --gamma-min), ranked "
                   "by consensus")
      ->check(CLI::IsMember({"tip-flirt"}));
  command
      ->add_option("--rank-by", options->rank_by,
                   "Score ranking answers for the P/R curve: confidence (default preset), gamma "
                   "(paper preset), consensus (tip-flirt) or score")
      ->check(CLI::IsMember({"confidence", "gamma", "consensus", "score"}));
  command->add_option("--json", options->json_path, "Write the figures as JSON to FILE");
  command->add_option("--queries", options->queries_path, "Write one TSV row per query to FILE");
  command->add_option("--curve", options->curve_path, "Write the precision-recall curve (TSV)");
  command->callback([options] { RunLocalize(*options); });
}

}  // namespace keyplace::cli
