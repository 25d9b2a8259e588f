#include "paper_parameters.hpp"

namespace keyplace::cli {

const std::vector<PaperParameter>& PaperParameters() {
  static const std::vector<PaperParameter> kParameters{
      {"l_g (m)", "Table V", 0.1, "cell size of the stability grid G"},
      {"s_min", "Table V", 0.3, "minimal stability score of a kept keypoint"},
      {"mu", "Table V", 10, "minimal unique descriptor pairs of a candidate submap"},
      {"gamma_min", "Table V", 0.4, "second geometric check, Eq. (10)"},
      {"lambda (m)", "Table V", 0.05, "max distance of a doubly matched pair (also 0.1)"},
      {"ns_min", "Section 3.1.1", 4, "lower bound of ns in the stability score"},
      {"descriptor chi2", "Section 3.1.1", 0.4, "similar descriptors: symmetric chi2 below this"},
      {"rho_min", "Section 3.1.3", 0.75, "submap complete when the overlap drops below"},
      {"l (m)", "Section 3.1.3", 0.5, "cell of the grid D of the distribution distance"},
      {"delta_max", "Section 5.2", 0.5, "and the distribution distance is at most this"},
      {"min keypoints", "Section 5.2", 10, "and the submap holds at least this many"},
      {"n_c", "Section 4.2", 500, "candidates verified"},
      {"RANSAC inlier (m)", "Section 4.1.1", 0.1, "acceptance threshold of an inlier"},
      {"min consensus", "Section 5.2", 9, "first geometric check: RANSAC inliers"},
      {"n_pos", "Section 5.2", 500, "starting positions of global localization"},
  };
  return kParameters;
}

}  // namespace keyplace::cli
