// The keyplace Python module: `import keyplace` (docs/PYTHON.md). Each binding file covers one
// part of the library; every function calls the library, the module holds no pipeline logic.

#include "bindings.hpp"

PYBIND11_MODULE(keyplace, module) {
  module.doc() =
      "keyplace: 2D LiDAR place recognition with map data reduction (FLIRT keypoints, submaps of "
      "stable keypoints, global localization, SLAM). Poses are numpy arrays [x_m, y_m, theta_rad]; "
      "errors of the library raise ValueError (bad input or configuration) or RuntimeError (files "
      "that cannot be read or written) with the library's message. See docs/PYTHON.md.";
  module.attr("__version__") = KEYPLACE_VERSION;
  keyplace::python::BindConfig(module);
  keyplace::python::BindIo(module);
  keyplace::python::BindFeatures(module);
  keyplace::python::BindMapping(module);
  keyplace::python::BindLocalization(module);
  keyplace::python::BindEvaluation(module);
  keyplace::python::BindMerge(module);
  keyplace::python::BindNavigation(module);
  keyplace::python::BindRelocalization(module);
}
