#include "paper_tables.hpp"

#include <algorithm>
#include <cctype>
#include <filesystem>

namespace keyplace::cli {

std::optional<std::string> DatasetName(const std::string& log_path) {
  std::string name = std::filesystem::path(log_path).filename().string();
  std::transform(name.begin(), name.end(), name.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  std::string base;
  if (name.rfind("fr079", 0) == 0) {
    base = "FR079";
  } else if (name.rfind("fr101", 0) == 0) {
    base = "FR101";
  } else if (name.rfind("intel", 0) == 0) {
    base = "Intel";
  } else {
    return std::nullopt;
  }
  if (name.find("raw") != std::string::npos) return base + "_r";
  if (name.find("corrected") != std::string::npos) return base;
  return std::nullopt;
}

const PaperMappingRow* PaperMapping(const std::string& dataset) {
  // Table II (corrected data, overlap criterion) and Table VI (raw data, ICP).
  struct Entry {
    const char* dataset;
    PaperMappingRow row;
  };
  static const Entry kRows[] = {
      {"FR079", {"II", 0.12, 5.20, 17.80, 0.45, 281, 0.057}},
      {"FR101", {"II", 0.12, 4.04, 14.79, 0.54, 72, 0.109}},
      {"Intel", {"II", 0.15, 5.83, 16.04, 0.46, 457, 0.075}},
      {"FR079_r", {"VI", 0.12, 7.95, 26.93, 0.37, 620, 0.31}},
      {"FR101_r", {"VI", 0.14, 9.95, 40.91, 0.35, 478, 0.46}},
      {"Intel_r", {"VI", 0.15, 7.69, 20.30, 0.40, 1772, 0.26}},
  };
  for (const Entry& entry : kRows) {
    if (dataset == entry.dataset) return &entry.row;
  }
  return nullptr;
}

}  // namespace keyplace::cli
