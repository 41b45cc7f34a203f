#pragma once

// The energy breakdown of a 3D system: one value per energy term of the system's list
// (terms/energy_term.hpp), with the terms' names, equations and plot titles. Everything that
// lists energies (results.h5 /steps/energies, the CSV columns, checkpoints, the plots)
// iterates it instead of naming terms.

#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace mresim::mess {

struct TermLabel {
  std::string name;      // dataset name under /steps/energies, CSV column E_<name>_J
  std::string equation;  // "eq. 4.62"
  std::string title;     // plot label
  bool in_total = true;  // false: reported only (eq. 4.73)
};
using TermLabels = std::vector<TermLabel>;

class MessEnergies {
 public:
  // No terms (a record not yet computed).
  MessEnergies() = default;
  // Zeros for the given terms (shared: every evaluation of one system uses the same labels).
  explicit MessEnergies(std::shared_ptr<const TermLabels> labels);
  // Zeros for terms of these labels (tests, readers).
  static MessEnergies of(TermLabels labels);

  std::size_t size() const { return values_.size(); }
  const TermLabel& label(std::size_t i) const { return (*labels_)[i]; }
  const std::shared_ptr<const TermLabels>& labels() const { return labels_; }
  double value(std::size_t i) const { return values_[i]; }
  double& value(std::size_t i) { return values_[i]; }

  bool has(std::string_view name) const { return index_of(name) < size(); }
  // The value of the term `name`; std::out_of_range if the list has no such term.
  double operator[](std::string_view name) const;
  double& operator[](std::string_view name);

  // The sum of the terms in the total, in list order: springs + volume + zeeman + dipole +
  // self + wca + load for the built-in terms (0 without terms).
  double total() const;

 private:
  std::size_t index_of(std::string_view name) const;
  std::size_t checked_index(std::string_view name) const;

  std::shared_ptr<const TermLabels> labels_;
  std::vector<double> values_;
};

}  // namespace mresim::mess
