#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <variant>
#include <vector>

namespace mresim::app {

// What `mresim info` prints: every quantity a run plan derives from its run file (reduced
// fields, stiffness constants, thresholds, step counts...), grouped in sections, in the order
// they were added. Lets a user check a run before spending time on it.
class InfoReport {
 public:
  struct Entry {
    std::string section;
    std::string key;
    std::variant<double, std::int64_t, std::string> value;
    std::string unit;
    std::string note;
  };

  // Each (section, key) may be added once; a second add throws std::logic_error.
  void add(std::string section, std::string key, double value, std::string unit,
           std::string note = {});
  void add_integer(std::string section, std::string key, std::int64_t value, std::string unit = {},
                   std::string note = {});
  void add_text(std::string section, std::string key, std::string value, std::string note = {});

  [[nodiscard]] const std::vector<Entry>& entries() const { return entries_; }

  // Sections as "[name]" headers with aligned "key  value unit  note" lines below; numbers with
  // 6 significant digits.
  [[nodiscard]] std::string to_text() const;
  // {"section": {"key": {"value": 0.04, "unit": "N/m", "note": "..."}}}, full precision.
  [[nodiscard]] nlohmann::json to_json() const;

 private:
  void push(Entry entry);

  std::vector<Entry> entries_;
};

}  // namespace mresim::app
