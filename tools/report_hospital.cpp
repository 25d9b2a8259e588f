#include "report_hospital.hpp"

#include <filesystem>
#include <optional>
#include <string>

#include <fmt/core.h>

namespace keyplace::cli {
namespace {

namespace fs = std::filesystem;
using A = ReportArtefacts;

std::string Metres(const std::optional<double>& mean_m, const std::optional<double>& std_m) {
  if (!mean_m) return "–";
  return std_m ? fmt::format("{:.3f} ± {:.3f} m", *mean_m, *std_m)
               : fmt::format("{:.3f} m", *mean_m);
}

// One split ("" = all relations, "local_", "loop_") of the relation JSON at `path`.
std::string Split(const std::optional<nlohmann::json>& relations, const std::string& prefix,
                  const std::string& path) {
  return Metres(Number(relations, prefix + "translation_mean_m", path),
                Number(relations, prefix + "translation_std_m", path));
}

}  // namespace

std::string HospitalSection(const ReportContext& context) {
  std::string html =
      "<h2 id=\"hospital\">SLAM in a building nobody tuned it on: the Freiburg hospital bag</h2>\n"
      "<p>The Freiburg University Hospital log of the SLAM benchmark, read from its ROS 1 bag, "
      "with the default configuration (chosen on FR079 and Intel; this bag is a check set). "
      "There are no corrected poses, so loops are not checked against ground truth; the relation "
      "error of Kümmerle et al. (2009) is. Ours splits it at 5 s between the two stamps (local) "
      "and the rest (loop); Cartographer's local / global split is its own.</p>\n";
  const std::string dir = A::HospitalSlamDir(context.settings);
  const std::string path = (fs::path(dir) / "slam.json").string();
  const std::optional<nlohmann::json> json = LoadJson(path);
  if (!json) {
    return html + MissingHtml(HowToMake(context, path) +
                              " (planned by a full report when DATA/fr-clinic.orig.bag and "
                              "DATA/fr-clinic.relations exist)");
  }
  std::optional<nlohmann::json> relations;
  if (json->contains("relations") && (*json)["relations"].is_object()) {
    relations = (*json)["relations"];
  }
  const std::optional<double> detected = Number(json, "loops_detected", path);
  const std::optional<double> used = Number(json, "loops_used", path);
  html +=
      "<table><tr><th></th><th>loops detected / used</th><th>all relations</th>"
      "<th>local</th><th>loop</th></tr>\n";
  html += fmt::format(
      "<tr><td>keyplace slam</td><td>{} / {}</td><td>{}</td><td>{}</td><td>{}</td></tr>\n",
      detected ? fmt::format("{:.0f}", *detected) : "–", used ? fmt::format("{:.0f}", *used) : "–",
      Split(relations, "", path), Split(relations, "local_", path),
      Split(relations, "loop_", path));
  // Published figures: Kümmerle et al. 2009 (all relations), Hess et al. 2016 (Cartographer).
  html +=
      "<tr><td>graph mapping (Kümmerle 2009)</td><td>–</td><td>0.143 ± 0.180 m</td>"
      "<td>–</td><td>–</td></tr>\n";
  html +=
      "<tr><td>Cartographer (Hess 2016)</td><td>–</td><td>–</td><td>0.108 ± 0.194 m</td>"
      "<td>5.2 m</td></tr>\n</table>\n";
  html += FigureHtml((fs::path(dir) / "figures/trajectory.png").string(),
                     "Trajectory of keyplace slam on the hospital bag, loops used in white",
                     HowToMake(context, (fs::path(dir) / "figures/trajectory.png").string()));
  return html;
}

}  // namespace keyplace::cli
