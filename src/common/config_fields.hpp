#pragma once
// Internal: the field table of a config struct. One table per struct lists every field once
// (name, unit, one line of doc, member); text I/O for map files, --set KEY=VALUE, YAML files and
// `keyplace dump-config` all go through it, so no field is parsed or printed by hand anywhere.
// Nested structs (e.g. PlaceRecognitionConfig::ransac) join with a dotted prefix.

#include <charconv>
#include <cmath>
#include <cstdint>
#include <functional>
#include <map>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "common/shown_text.hpp"

namespace keyplace {

/// The shortest text that reads back as the same double.
inline std::string FormatConfigDouble(double value) {
  char text[32];
  const auto result = std::to_chars(text, text + sizeof(text), value);
  return std::string(text, result.ptr);
}

/// What a table knows about one field, for documentation (dump-config).
struct ConfigFieldDoc {
  std::string name;  // dotted for nested fields: "ransac.iterations"
  std::string unit;  // "m", "rad", "" for counts and switches
  std::string doc;   // one line; enums list their values
};

template <typename Config>
class ConfigFields {
 public:
  struct Field {
    ConfigFieldDoc doc;
    std::function<std::string(const Config&)> get;
    // Throws std::invalid_argument with what is wrong with the text (without the field's name).
    std::function<void(const std::string&, Config&)> set;
  };

  /// `struct_name` prefixes every error message ("MappingConfig.min_stability: ...").
  explicit ConfigFields(std::string struct_name) : struct_name_(std::move(struct_name)) {}

  ConfigFields& Double(const char* name, double Config::*member, const char* unit,
                       const char* doc) {
    return Add(
        {name, unit, doc}, [member](const Config& c) { return FormatConfigDouble(c.*member); },
        [member](const std::string& text, Config& c) {
          const double value = ParseNumber<double>(text, "a number");
          // No setting means "unlimited" by infinity (0 switches things off), and an infinite
          // size or distance would only fail later, as an allocation or a NaN far from here.
          if (!std::isfinite(value))
            throw std::invalid_argument("'" + ShownText(text) + "' is not finite");
          c.*member = value;
        });
  }

  template <typename Integer>
  ConfigFields& Int(const char* name, Integer Config::*member, const char* unit, const char* doc) {
    return Add(
        {name, unit, doc}, [member](const Config& c) { return std::to_string(c.*member); },
        [member](const std::string& text, Config& c) {
          c.*member = ParseNumber<Integer>(text, "an integer");
        });
  }

  ConfigFields& Text(const char* name, std::string Config::*member, const char* unit,
                     const char* doc) {
    return Add(
        {name, unit, doc}, [member](const Config& c) { return c.*member; },
        [member](const std::string& text, Config& c) { c.*member = text; });
  }

  ConfigFields& Bool(const char* name, bool Config::*member, const char* doc) {
    return Add(
        {name, "", doc},
        [member](const Config& c) { return std::string(c.*member ? "true" : "false"); },
        [member](const std::string& text, Config& c) {
          if (text == "true" || text == "1") {
            c.*member = true;
          } else if (text == "false" || text == "0") {
            c.*member = false;
          } else {
            throw std::invalid_argument("'" + ShownText(text) + "' is not true or false");
          }
        });
  }

  template <typename EnumType>
  ConfigFields& Enum(const char* name, EnumType Config::*member,
                     std::vector<std::pair<EnumType, const char*>> names, const char* doc) {
    std::string values;
    for (const auto& entry : names)
      values += (values.empty() ? "" : " | ") + std::string(entry.second);
    return Add(
        {name, "", std::string(doc) + " (" + values + ")"},
        [member, names](const Config& c) {
          for (const auto& [value, text] : names) {
            if (value == c.*member) return std::string(text);
          }
          return std::string("?");
        },
        [member, names, values](const std::string& text, Config& c) {
          for (const auto& [value, value_text] : names) {
            if (text == value_text) {
              c.*member = value;
              return;
            }
          }
          throw std::invalid_argument("'" + ShownText(text) + "' is not one of " + values);
        });
  }

  /// Every field of `sub` under "name.", reading and writing `config.*member`.
  template <typename Sub>
  ConfigFields& Nested(const char* name, Sub Config::*member, const ConfigFields<Sub>& sub) {
    for (const auto& field : sub.fields()) {
      ConfigFieldDoc doc = field.doc;
      doc.name = std::string(name) + "." + doc.name;
      fields_.push_back({doc, [member, get = field.get](const Config& c) { return get(c.*member); },
                         [member, set = field.set](const std::string& text, Config& c) {
                           set(text, c.*member);
                         }});
    }
    return *this;
  }

  const std::vector<Field>& fields() const { return fields_; }
  const std::string& struct_name() const { return struct_name_; }

  /// Every field as (name, text), in table order.
  std::vector<std::pair<std::string, std::string>> ToKeyValues(const Config& config) const {
    std::vector<std::pair<std::string, std::string>> values;
    for (const Field& field : fields_) values.emplace_back(field.doc.name, field.get(config));
    return values;
  }

  /// Sets one field; throws std::invalid_argument naming the struct, key and value.
  void Set(const std::string& key, const std::string& text, Config& config) const {
    const Field* field = Find(key);
    if (field == nullptr) {
      throw std::invalid_argument(struct_name_ + ": unknown key '" + ShownText(key) + "'");
    }
    try {
      field->set(text, config);
    } catch (const std::invalid_argument& error) {
      throw std::invalid_argument(struct_name_ + "." + key + ": " + error.what());
    }
  }

  /// Sets the named fields; throws std::invalid_argument naming an unknown key or a bad value.
  void Apply(const std::map<std::string, std::string>& values, Config& config) const {
    for (const auto& [key, text] : values) Set(key, text, config);
  }

  const Field* Find(const std::string& key) const {
    for (const Field& field : fields_) {
      if (field.doc.name == key) return &field;
    }
    return nullptr;
  }

 private:
  ConfigFields& Add(ConfigFieldDoc doc, std::function<std::string(const Config&)> get,
                    std::function<void(const std::string&, Config&)> set) {
    fields_.push_back({std::move(doc), std::move(get), std::move(set)});
    return *this;
  }

  template <typename Number>
  static Number ParseNumber(const std::string& text, const char* kind) {
    Number value{};
    const char* begin = text.data();
    const char* end = text.data() + text.size();
    const auto result = std::from_chars(begin, end, value);
    if (text.empty() || result.ec != std::errc() || result.ptr != end) {
      throw std::invalid_argument("'" + ShownText(text) + "' is not " + kind);
    }
    return value;
  }

  std::string struct_name_;
  std::vector<Field> fields_;
};

}  // namespace keyplace
