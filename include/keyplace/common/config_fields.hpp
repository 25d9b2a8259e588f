#pragma once
// Text form of a config struct's fields, for map files, --set KEY=VALUE and dump-config: one
// table of (name, member) per struct instead of hand-written parsers.

#include <charconv>
#include <cstdint>
#include <functional>
#include <map>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace keyplace {

/// The shortest text that reads back as the same double.
inline std::string FormatConfigDouble(double value) {
  char text[32];
  const auto result = std::to_chars(text, text + sizeof(text), value);
  return std::string(text, result.ptr);
}

template <typename Config>
class ConfigFields {
 public:
  /// `struct_name` prefixes every error message ("MappingConfig.min_stability: ...").
  explicit ConfigFields(std::string struct_name) : struct_name_(std::move(struct_name)) {}

  ConfigFields& Double(const char* name, double Config::*member) {
    return Add(
        name, [member](const Config& c) { return FormatConfigDouble(c.*member); },
        [prefix = struct_name_, name, member](const std::string& text, Config& c) {
          c.*member = ParseNumber<double>(prefix, name, text, "a number");
        });
  }

  template <typename Integer>
  ConfigFields& Int(const char* name, Integer Config::*member) {
    return Add(
        name, [member](const Config& c) { return std::to_string(c.*member); },
        [prefix = struct_name_, name, member](const std::string& text, Config& c) {
          c.*member = ParseNumber<Integer>(prefix, name, text, "an integer");
        });
  }

  ConfigFields& Bool(const char* name, bool Config::*member) {
    return Add(
        name, [member](const Config& c) { return std::string(c.*member ? "true" : "false"); },
        [prefix = struct_name_, name, member](const std::string& text, Config& c) {
          if (text == "true" || text == "1") {
            c.*member = true;
          } else if (text == "false" || text == "0") {
            c.*member = false;
          } else {
            Fail(prefix, name, "'" + text + "' is not true or false");
          }
        });
  }

  template <typename EnumType>
  ConfigFields& Enum(const char* name, EnumType Config::*member,
                     std::vector<std::pair<EnumType, const char*>> names) {
    return Add(
        name,
        [member, names](const Config& c) {
          for (const auto& [value, text] : names) {
            if (value == c.*member) return std::string(text);
          }
          return std::string("?");
        },
        [prefix = struct_name_, name, member, names](const std::string& text, Config& c) {
          std::string accepted;
          for (const auto& [value, value_text] : names) {
            if (text == value_text) {
              c.*member = value;
              return;
            }
            accepted += (accepted.empty() ? "" : ", ") + std::string(value_text);
          }
          Fail(prefix, name, "'" + text + "' is not one of " + accepted);
        });
  }

  /// Every field as (name, text), in table order.
  std::vector<std::pair<std::string, std::string>> ToKeyValues(const Config& config) const {
    std::vector<std::pair<std::string, std::string>> values;
    for (const Field& field : fields_) values.emplace_back(field.name, field.get(config));
    return values;
  }

  /// Sets the named fields; throws std::invalid_argument naming an unknown key or a bad value.
  void Apply(const std::map<std::string, std::string>& values, Config& config) const {
    for (const auto& [key, text] : values) {
      const Field* field = Find(key);
      if (field == nullptr) {
        throw std::invalid_argument(struct_name_ + ": unknown key '" + key + "'");
      }
      field->set(text, config);
    }
  }

 private:
  struct Field {
    std::string name;
    std::function<std::string(const Config&)> get;
    std::function<void(const std::string&, Config&)> set;
  };

  ConfigFields& Add(const char* name, std::function<std::string(const Config&)> get,
                    std::function<void(const std::string&, Config&)> set) {
    fields_.push_back({name, std::move(get), std::move(set)});
    return *this;
  }

  const Field* Find(const std::string& key) const {
    for (const Field& field : fields_) {
      if (field.name == key) return &field;
    }
    return nullptr;
  }

  [[noreturn]] static void Fail(const std::string& prefix, const std::string& name,
                                const std::string& what) {
    throw std::invalid_argument(prefix + "." + name + ": " + what);
  }

  template <typename Number>
  static Number ParseNumber(const std::string& prefix, const std::string& name,
                            const std::string& text, const char* kind) {
    Number value{};
    const char* begin = text.data();
    const char* end = text.data() + text.size();
    const auto result = std::from_chars(begin, end, value);
    if (text.empty() || result.ec != std::errc() || result.ptr != end) {
      Fail(prefix, name, "'" + text + "' is not " + kind);
    }
    return value;
  }

  std::string struct_name_;
  std::vector<Field> fields_;
};

}  // namespace keyplace
