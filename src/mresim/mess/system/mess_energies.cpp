#include "mresim/mess/system/mess_energies.hpp"

#include <stdexcept>

namespace mresim::mess {

MessEnergies::MessEnergies(std::shared_ptr<const TermLabels> labels)
    : labels_(std::move(labels)), values_(labels_ ? labels_->size() : 0, 0.0) {}

MessEnergies MessEnergies::of(TermLabels labels) {
  return MessEnergies(std::make_shared<const TermLabels>(std::move(labels)));
}

std::size_t MessEnergies::index_of(std::string_view name) const {
  for (std::size_t i = 0; i < size(); ++i) {
    if (label(i).name == name) return i;
  }
  return size();
}

std::size_t MessEnergies::checked_index(std::string_view name) const {
  const std::size_t i = index_of(name);
  if (i == size())
    throw std::out_of_range("MessEnergies: no energy term '" + std::string(name) + "'");
  return i;
}

double MessEnergies::operator[](std::string_view name) const {
  return values_[checked_index(name)];
}

double& MessEnergies::operator[](std::string_view name) { return values_[checked_index(name)]; }

double MessEnergies::total() const {
  // Left to right from the first term in the total, as the fixed sum of the original fields.
  double sum = 0.0;
  bool first = true;
  for (std::size_t i = 0; i < size(); ++i) {
    if (!label(i).in_total) continue;
    sum = first ? values_[i] : sum + values_[i];
    first = false;
  }
  return sum;
}

}  // namespace mresim::mess
