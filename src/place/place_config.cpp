#include "keyplace/place/place_config.hpp"

#include <charconv>
#include <functional>
#include <stdexcept>
#include <string>

namespace keyplace {
namespace {

void Require(bool ok, const std::string& field, const std::string& rule) {
  if (!ok) throw std::invalid_argument("PlaceRecognitionConfig." + field + " " + rule);
}

std::string FormatDouble(double value) {
  char text[32];
  const auto result = std::to_chars(text, text + sizeof(text), value);
  return std::string(text, result.ptr);
}

double ParseDouble(const std::string& key, const std::string& text) {
  try {
    std::size_t used = 0;
    const double value = std::stod(text, &used);
    if (used == text.size()) return value;
  } catch (const std::exception&) {
  }
  throw std::invalid_argument("PlaceRecognitionConfig." + key + ": '" + text + "' is not a number");
}

long long ParseInteger(const std::string& key, const std::string& text) {
  try {
    std::size_t used = 0;
    const long long value = std::stoll(text, &used);
    if (used == text.size()) return value;
  } catch (const std::exception&) {
  }
  throw std::invalid_argument("PlaceRecognitionConfig." + key + ": '" + text +
                              "' is not an integer");
}

bool ParseBool(const std::string& key, const std::string& text) {
  if (text == "true" || text == "1") return true;
  if (text == "false" || text == "0") return false;
  throw std::invalid_argument("PlaceRecognitionConfig." + key + ": '" + text +
                              "' is not true/false");
}

template <typename Enum>
struct EnumNames {
  std::vector<std::pair<Enum, const char*>> names;

  std::string ToText(Enum value) const {
    for (const auto& [candidate, name] : names) {
      if (candidate == value) return name;
    }
    return "?";
  }
  Enum FromText(const std::string& key, const std::string& text) const {
    std::string accepted;
    for (const auto& [candidate, name] : names) {
      if (text == name) return candidate;
      accepted += (accepted.empty() ? "" : ", ") + std::string(name);
    }
    throw std::invalid_argument("PlaceRecognitionConfig." + key + ": '" + text +
                                "' is not one of " + accepted);
  }
};

using Config = PlaceRecognitionConfig;
const EnumNames<Config::PairMatching> kPairMatching{
    {{Config::PairMatching::kQueryOrder, "query_order"},
     {Config::PairMatching::kGlobalGreedy, "global_greedy"}}};
const EnumNames<Config::GammaCounting> kGammaCounting{
    {{Config::GammaCounting::kUniquePairs, "unique_pairs"},
     {Config::GammaCounting::kPerKeypoint, "per_keypoint"}}};
const EnumNames<Config::Selection> kSelection{
    {{Config::Selection::kFirstVerified, "first_verified"},
     {Config::Selection::kBestScore, "best_score"}}};
const EnumNames<Config::Score> kScore{{{Config::Score::kGamma, "gamma"},
                                       {Config::Score::kConsensus, "consensus"},
                                       {Config::Score::kConsensusGamma, "consensus_gamma"}}};

// One accessor per field: text out, text in.
struct Field {
  const char* name;
  std::function<std::string(const Config&)> get;
  std::function<void(const std::string&, Config&)> set;
};

#define KEYPLACE_DOUBLE_FIELD(f)                                                                   \
  Field {                                                                                          \
#f, [](const Config& c) { return FormatDouble(c.f); }, [](const std::string& t,                \
                                                              Config&                              \
                                                                  c) { c.f = ParseDouble(#f, t); } \
  }
#define KEYPLACE_INT_FIELD(f)                                                       \
  Field {                                                                           \
#f, [](const Config& c) { return std::to_string(c.f); },                          \
        [](const std::string& t, Config& c) {                                         \
          c.f = static_cast<decltype(c.f)>(ParseInteger(#f, t));                      \
        } \
  }
#define KEYPLACE_BOOL_FIELD(f)                                                                        \
  Field {                                                                                             \
#f, [](const Config&                                                                              \
               c) { return std::string(c.f ? "true" : "false"); },                                    \
                                                                [](const std::string& t,              \
                                                                   Config&                            \
                                                                       c) { c.f =                     \
                                                                                ParseBool(#f, t); } \
  }
#define KEYPLACE_ENUM_FIELD(f, names)                                                           \
  Field {                                                                                       \
#f, [](const Config&                                                                        \
               c) { return names.ToText(c.f); }, [](const std::string& t,                       \
                                                    Config& c) { c.f = names.FromText(#f, t); } \
  }

const std::vector<Field>& Fields() {
  static const std::vector<Field> kFields = {
      KEYPLACE_INT_FIELD(min_pairs),
      KEYPLACE_INT_FIELD(max_candidates),
      KEYPLACE_DOUBLE_FIELD(descriptor_match_chi2),
      KEYPLACE_ENUM_FIELD(pair_matching, kPairMatching),
      KEYPLACE_DOUBLE_FIELD(inlier_distance_m),
      KEYPLACE_INT_FIELD(ransac_iterations),
      KEYPLACE_INT_FIELD(exhaustive_hypotheses_max_pairs),
      KEYPLACE_DOUBLE_FIELD(rigidity_m2),
      KEYPLACE_BOOL_FIELD(refine),
      KEYPLACE_INT_FIELD(seed),
      KEYPLACE_INT_FIELD(verification_neighbours),
      KEYPLACE_INT_FIELD(min_consensus),
      KEYPLACE_DOUBLE_FIELD(min_gamma),
      KEYPLACE_DOUBLE_FIELD(double_match_m),
      KEYPLACE_ENUM_FIELD(gamma_counting, kGammaCounting),
      KEYPLACE_ENUM_FIELD(selection, kSelection),
      KEYPLACE_ENUM_FIELD(score, kScore),
      KEYPLACE_DOUBLE_FIELD(distinct_distance_m),
      KEYPLACE_DOUBLE_FIELD(distinct_angle_deg),
      KEYPLACE_DOUBLE_FIELD(ambiguity_ratio),
      KEYPLACE_DOUBLE_FIELD(min_confidence),
      KEYPLACE_INT_FIELD(confidence_consensus),
  };
  return kFields;
}

}  // namespace

PlaceRecognitionConfig PaperPlaceConfig() {
  PlaceRecognitionConfig config;
  config.pair_matching = PlaceRecognitionConfig::PairMatching::kQueryOrder;
  config.exhaustive_hypotheses_max_pairs = 0;
  config.selection = PlaceRecognitionConfig::Selection::kFirstVerified;
  config.score = PlaceRecognitionConfig::Score::kGamma;
  config.ambiguity_ratio = 1.0;
  config.verification_neighbours = 0;
  return config;
}

PlaceRecognitionConfig PlacePreset(const std::string& name) {
  if (name == "default") return PlaceRecognitionConfig{};
  if (name == "paper") return PaperPlaceConfig();
  throw std::invalid_argument("unknown place recognition preset '" + name +
                              "' (expected default or paper)");
}

void Validate(const PlaceRecognitionConfig& config) {
  Require(config.min_pairs >= 2, "min_pairs", "must be >= 2");
  Require(config.max_candidates >= 1, "max_candidates", "must be >= 1");
  Require(config.descriptor_match_chi2 > 0.0, "descriptor_match_chi2", "must be positive");
  Require(config.inlier_distance_m > 0.0, "inlier_distance_m", "must be positive");
  Require(config.ransac_iterations >= 1, "ransac_iterations", "must be >= 1");
  Require(config.exhaustive_hypotheses_max_pairs >= 0, "exhaustive_hypotheses_max_pairs",
          "must be >= 0");
  Require(config.rigidity_m2 > 0.0, "rigidity_m2", "must be positive");
  Require(config.verification_neighbours >= 0, "verification_neighbours", "must be >= 0");
  Require(config.min_consensus >= 2, "min_consensus", "must be >= 2");
  Require(config.min_gamma >= 0.0 && config.min_gamma <= 1.0, "min_gamma", "must lie in [0, 1]");
  Require(config.double_match_m > 0.0, "double_match_m", "must be positive");
  Require(config.distinct_distance_m > 0.0, "distinct_distance_m", "must be positive");
  Require(config.distinct_angle_deg > 0.0, "distinct_angle_deg", "must be positive");
  Require(config.ambiguity_ratio > 0.0, "ambiguity_ratio", "must be positive");
  Require(config.min_confidence >= 0.0 && config.min_confidence <= 1.0, "min_confidence",
          "must lie in [0, 1]");
  Require(config.confidence_consensus >= 1, "confidence_consensus", "must be >= 1");
}

std::vector<std::pair<std::string, std::string>> ToKeyValues(const PlaceRecognitionConfig& config) {
  std::vector<std::pair<std::string, std::string>> values;
  for (const Field& field : Fields()) values.emplace_back(field.name, field.get(config));
  return values;
}

void ApplyKeyValues(const std::map<std::string, std::string>& values,
                    PlaceRecognitionConfig& config) {
  for (const auto& [key, text] : values) {
    bool known = false;
    for (const Field& field : Fields()) {
      if (key == field.name) {
        field.set(text, config);
        known = true;
        break;
      }
    }
    if (!known) throw std::invalid_argument("PlaceRecognitionConfig has no field '" + key + "'");
  }
  Validate(config);
}

}  // namespace keyplace
