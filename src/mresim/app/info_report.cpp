#include "mresim/app/info_report.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <stdexcept>

namespace mresim::app {

namespace {

std::string value_text(const InfoReport::Entry& entry) {
  std::string text;
  if (const auto* x = std::get_if<double>(&entry.value)) {
    text = fmt::format("{:.6g}", *x);
  } else if (const auto* n = std::get_if<std::int64_t>(&entry.value)) {
    text = fmt::format("{}", *n);
  } else {
    text = std::get<std::string>(entry.value);
  }
  return entry.unit.empty() ? text : fmt::format("{} {}", text, entry.unit);
}

}  // namespace

void InfoReport::push(Entry entry) {
  const bool duplicate = std::any_of(entries_.begin(), entries_.end(), [&](const Entry& e) {
    return e.section == entry.section && e.key == entry.key;
  });
  if (duplicate) {
    throw std::logic_error(
        fmt::format("InfoReport: [{}] {} was added twice", entry.section, entry.key));
  }
  entries_.push_back(std::move(entry));
}

void InfoReport::add(std::string section, std::string key, double value, std::string unit,
                     std::string note) {
  push({std::move(section), std::move(key), value, std::move(unit), std::move(note)});
}

void InfoReport::add_integer(std::string section, std::string key, std::int64_t value,
                             std::string unit, std::string note) {
  push({std::move(section), std::move(key), value, std::move(unit), std::move(note)});
}

void InfoReport::add_text(std::string section, std::string key, std::string value,
                          std::string note) {
  push({std::move(section), std::move(key), std::move(value), {}, std::move(note)});
}

std::string InfoReport::to_text() const {
  // Sections in order of first appearance, entries in order of addition.
  std::vector<std::string> sections;
  for (const auto& e : entries_) {
    if (std::find(sections.begin(), sections.end(), e.section) == sections.end()) {
      sections.push_back(e.section);
    }
  }
  std::string out;
  for (const auto& section : sections) {
    std::size_t key_width = 0;
    std::size_t value_width = 0;
    for (const auto& e : entries_) {
      if (e.section != section) continue;
      key_width = std::max(key_width, e.key.size());
      // Notes line up after the widest annotated value; a long unannotated value (a title)
      // must not push every note far to the right.
      if (!e.note.empty()) value_width = std::max(value_width, value_text(e).size());
    }
    if (!out.empty()) out += '\n';
    out += fmt::format("[{}]\n", section);
    for (const auto& e : entries_) {
      if (e.section != section) continue;
      if (e.note.empty()) {
        out += fmt::format("  {:<{}}  {}\n", e.key, key_width, value_text(e));
      } else {
        out += fmt::format("  {:<{}}  {:<{}}  {}\n", e.key, key_width, value_text(e), value_width,
                           e.note);
      }
    }
  }
  return out;
}

nlohmann::json InfoReport::to_json() const {
  nlohmann::json out = nlohmann::json::object();
  for (const auto& e : entries_) {
    nlohmann::json item;
    std::visit([&](const auto& v) { item["value"] = v; }, e.value);
    item["unit"] = e.unit;
    item["note"] = e.note;
    out[e.section][e.key] = std::move(item);
  }
  return out;
}

}  // namespace mresim::app
