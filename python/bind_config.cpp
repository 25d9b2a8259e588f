// keyplace.Config: the whole configuration (keyplace dump-config), from a preset, a YAML file and
// "section.key" -> value overrides, as the CLI's --preset, --config and --set.

#include <string>
#include <utility>
#include <vector>

#include <pybind11/stl.h>

#include "bindings.hpp"

namespace keyplace::python {
namespace {

PyConfig MakeConfig(const std::string& preset, const py::object& overrides,
                    const py::object& file) {
  PyConfig config;
  config.preset = preset;
  config.config = PresetConfig(preset);
  // The file and the overrides validated together, once (as --config and --set).
  ConfigBuilder builder(config.config);
  if (!file.is_none()) builder.File(py::str(file).cast<std::string>());
  AddOverrides(overrides, builder);
  config.config = builder.Build();
  return config;
}

std::string Get(const PyConfig& config, const std::string& key) {
  for (const auto& [name, value] : ConfigKeyValues(config.config)) {
    if (name == key) return value;
  }
  throw py::key_error("unknown configuration key '" + key + "' (keyplace dump-config lists them)");
}

}  // namespace

void BindConfig(py::module_& module) {
  py::class_<PyConfig>(
      module, "Config",
      "The whole keyplace configuration: one section per module (input, "
      "features, odometry, mapping, place, slam, localization, evaluation, grid, "
      "merge, node); `keyplace dump-config --all` lists every key with its unit and doc.")
      .def(py::init(&MakeConfig), py::arg("preset") = "default", py::arg("overrides") = py::none(),
           py::arg("file") = py::none(),
           "Config(preset='default', overrides=None, file=None): the preset ('default', 'paper' "
           "or 'strict'), then the YAML file, then overrides {'section.key': value} (as --set), "
           "validated once after all of them. Raises ValueError naming the key for an unknown "
           "key or an invalid value.")
      .def_readonly("preset", &PyConfig::preset, "The preset the configuration started from.")
      .def(
          "set",
          [](PyConfig& config, const std::string& key, const py::object& value) {
            py::dict overrides;
            overrides[py::str(key)] = value;
            config = ResolveConfig(py::cast(config), overrides);
          },
          py::arg("key"), py::arg("value"),
          "Sets one field, e.g. set('place.min_pairs', 12); ValueError for a bad key or value.")
      .def("get", &Get, py::arg("key"), "The value of a field as text (KeyError if unknown).")
      .def("__getitem__", &Get)
      .def(
          "to_dict",
          [](const PyConfig& config) {
            py::dict out;
            for (const auto& [key, value] : ConfigKeyValues(config.config)) {
              out[py::str(key)] = value;
            }
            return out;
          },
          "Every field as {'section.key': text value}, in table order.")
      .def(
          "to_yaml", [](const PyConfig& config) { return ConfigToYaml(config.config); },
          "The configuration as YAML (as keyplace dump-config writes it).")
      .def("__repr__", [](const PyConfig& config) {
        return "<keyplace.Config preset='" + config.preset + "'>";
      });
  module.def("config_presets", &ConfigPresetNames, "The names of the configuration presets.");
}

}  // namespace keyplace::python
