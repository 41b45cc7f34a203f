#pragma once

// The promises an example's header makes ("Expect: ..."), stated as checks in a data file under
// tests/data/examples/ (format: tests/data/examples/README.md), evaluated against the results.h5
// of a run of that example. The evaluator knows nothing about any one example: every number
// lives in the data file.

#include <fmt/format.h>
#include <hdf5.h>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <numbers>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "../../support/hdf5_read.hpp"

namespace mresim::testing::promises {

// What a run wrote, per relaxation step and per modulus fit, in the units the data files use.
struct RunData {
  std::vector<double> field_mT;          // /steps/field_projection
  std::vector<double> load;              // /steps/load_value (rad, strain or Pa)
  std::vector<double> separation_um;     // /steps/separation (closest pair of centres)
  std::vector<double> m_along_ms;        // /steps/magnetization_projection (units of Ms)
  std::vector<double> wca_energy_j;      // /steps/energies/wca
  std::vector<double> magnetostriction;  // /steps/magnetostriction (box strain along the field)
  std::vector<double> pair_angle_deg;    // /steps/pair_angle, degrees
  std::filesystem::path results;         // for the energies of other terms (energy_J)
  std::vector<std::int64_t> cluster_count, largest_cluster, converged, valid;
  std::vector<std::vector<std::int64_t>> cluster_id;  // [step][particle]
  std::vector<std::vector<double>> displacement_um;   // [step][3 * particle + axis], c - c_0
  std::vector<int> leg;                               // field legs, see field_legs()
  bool has_fits = false;
  std::vector<double> fit_field_mT, modulus_kpa, mr_effect_percent;
  std::vector<std::int64_t> fit_valid;
};

// Legs of a field sequence: a new leg starts at the first step after the field turns, so the
// turning point belongs to the leg that reached it. A mess_hysteresis loop 0 -> max -> -max ->
// max has legs 0 (up), 1 (down), 2 (up again).
inline std::vector<int> field_legs(const std::vector<double>& field) {
  std::vector<int> legs(field.size(), 0);
  int leg = 0;
  int direction = 0;
  for (std::size_t i = 1; i < field.size(); ++i) {
    const double d = field[i] - field[i - 1];
    const int sign = d > 0 ? 1 : (d < 0 ? -1 : 0);
    if (sign != 0 && direction != 0 && sign != direction) ++leg;
    if (sign != 0) direction = sign;
    legs[i] = leg;
  }
  return legs;
}

inline bool has_dataset(const std::filesystem::path& file, const char* path) {
  const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  if (f < 0) return false;
  const bool found =
      H5Lexists(f, "/analysis", H5P_DEFAULT) > 0 && H5Lexists(f, path, H5P_DEFAULT) > 0;
  H5Fclose(f);
  return found;
}

inline std::vector<double> scaled(std::vector<double> v, double factor) {
  for (auto& x : v) x *= factor;
  return v;
}

inline RunData read_run(const std::filesystem::path& results) {
  const Hdf5Reader h5(results);
  RunData r;
  r.results = results;
  r.field_mT = scaled(h5.doubles("/steps/field_projection"), 1e3);
  r.load = h5.doubles("/steps/load_value");
  r.separation_um = scaled(h5.doubles("/steps/separation"), 1e6);
  r.m_along_ms = h5.doubles("/steps/magnetization_projection");
  r.wca_energy_j = h5.doubles("/steps/energies/wca");
  r.magnetostriction = h5.doubles("/steps/magnetostriction");
  r.pair_angle_deg = scaled(h5.doubles("/steps/pair_angle"), 180.0 / std::numbers::pi);
  r.cluster_count = h5.ints("/steps/cluster_count");
  r.largest_cluster = h5.ints("/steps/largest_cluster");
  r.converged = h5.ints("/steps/solver/converged");
  r.valid = h5.ints("/steps/valid");
  const std::size_t steps = r.field_mT.size();
  const auto ids = h5.ints("/steps/cluster_id");
  const auto centres = h5.doubles("/steps/centres");
  const auto initial = h5.doubles("/lattice/initial_centres");
  const std::size_t np = steps > 0 ? ids.size() / steps : 0;
  for (std::size_t s = 0; s < steps; ++s) {
    r.cluster_id.emplace_back(ids.begin() + static_cast<std::ptrdiff_t>(s * np),
                              ids.begin() + static_cast<std::ptrdiff_t>((s + 1) * np));
    std::vector<double> d(3 * np);
    for (std::size_t k = 0; k < 3 * np; ++k) d[k] = 1e6 * (centres[s * 3 * np + k] - initial[k]);
    r.displacement_um.push_back(std::move(d));
  }
  r.leg = field_legs(r.field_mT);
  r.has_fits = has_dataset(results, "/analysis/modulus");
  if (r.has_fits) {
    r.fit_field_mT = scaled(h5.doubles("/analysis/field_magnitude"), 1e3);
    r.modulus_kpa = scaled(h5.doubles("/analysis/modulus"), 1e-3);
    r.mr_effect_percent = h5.doubles("/analysis/mr_effect");
    r.fit_valid = h5.ints("/analysis/valid");
  }
  return r;
}

// Quantities of one modulus fit per field (the rows of /analysis); all others are per step.
inline bool is_fit_quantity(const std::string& q) {
  return q == "modulus_kPa" || q == "mr_effect_percent" || q == "fit_valid";
}

inline bool near(double a, double b) { return std::abs(a - b) <= 1e-9 * (1.0 + std::abs(b)); }

// The indices (steps, or fit rows) a selector picks, in order. Keys (all optional, all must
// match): step, leg, B_mT, load, B_nonzero.
inline std::vector<std::size_t> select(const RunData& r, bool fits, const nlohmann::json& at) {
  static const std::set<std::string> keys{"step", "leg", "B_mT", "load", "B_nonzero"};
  for (const auto& [key, value] : at.items()) {
    if (!keys.contains(key)) throw std::runtime_error("unknown selector key '" + key + "'");
    if (fits && key != "B_mT") throw std::runtime_error("fit quantities select by B_mT only");
  }
  const std::size_t n = fits ? r.fit_field_mT.size() : r.field_mT.size();
  std::vector<std::size_t> out;
  for (std::size_t i = 0; i < n; ++i) {
    const double b = fits ? r.fit_field_mT[i] : r.field_mT[i];
    if (at.contains("B_mT") && !near(b, at["B_mT"].get<double>())) continue;
    if (fits) {
      out.push_back(i);
      continue;
    }
    if (at.contains("step") && i != at["step"].get<std::size_t>()) continue;
    if (at.contains("leg") && r.leg[i] != at["leg"].get<int>()) continue;
    if (at.contains("load") && !near(r.load[i], at["load"].get<double>())) continue;
    if (at.contains("B_nonzero") && (b != 0.0) != at["B_nonzero"].get<bool>()) continue;
    out.push_back(i);
  }
  return out;
}

// Clusters of exactly two particles at one step.
inline double pair_clusters(const std::vector<std::int64_t>& ids) {
  std::vector<int> size(ids.size() + 1, 0);
  for (const auto id : ids) {
    if (id >= 0 && static_cast<std::size_t>(id) < size.size()) ++size[static_cast<std::size_t>(id)];
  }
  double pairs = 0;
  for (const int s : size) pairs += s == 2 ? 1 : 0;
  return pairs;
}

// The value of a check's quantity at index i (a step, or a fit row for fit quantities).
inline double quantity(const RunData& r, const nlohmann::json& check, std::size_t i) {
  const std::string q = check.at("quantity").get<std::string>();
  if (q == "modulus_kPa") return r.modulus_kpa[i];
  if (q == "mr_effect_percent") return r.mr_effect_percent[i];
  if (q == "fit_valid") return static_cast<double>(r.fit_valid[i]);
  if (q == "separation_um") return r.separation_um[i];
  if (q == "M_along_Ms") return r.m_along_ms[i];
  if (q == "wca_energy_J") return r.wca_energy_j[i];
  if (q == "magnetostriction") return r.magnetostriction[i];
  if (q == "pair_angle_deg") return r.pair_angle_deg[i];
  if (q == "energy_J") {  // with "term": the dataset /steps/energies/<term>
    return Hdf5Reader(r.results)
        .doubles("/steps/energies/" + check.at("term").get<std::string>())
        .at(i);
  }
  if (q == "cluster_count") return static_cast<double>(r.cluster_count[i]);
  if (q == "largest_cluster") return static_cast<double>(r.largest_cluster[i]);
  if (q == "pair_clusters") return pair_clusters(r.cluster_id[i]);
  if (q == "converged") return static_cast<double>(r.converged[i]);
  if (q == "valid") return static_cast<double>(r.valid[i]);
  if (q == "centre_displacement_um") {
    const auto particle = check.at("particle").get<std::size_t>();
    const std::string axis = check.at("axis").get<std::string>();
    const std::size_t a = axis == "x" ? 0 : (axis == "y" ? 1 : 2);
    if (axis != "x" && axis != "y" && axis != "z") throw std::runtime_error("axis " + axis);
    return r.displacement_um[i].at(3 * particle + a);
  }
  throw std::runtime_error("unknown quantity '" + q + "'");
}

inline std::string describe(const nlohmann::json& check) {
  return fmt::format("[{}] {} at {}", check.value("claim", std::string("?")),
                     check.at("quantity").dump(), check.at("at").dump());
}

// Failures of one check (empty when it holds). Forms: min/max bounds, or equals, on the value
// at every selected index; with `minus` (`plus`), on the value minus (plus) the value at the
// index that selector picks (paired in order: both selectors must pick equally many indices).
inline std::vector<std::string> evaluate(const RunData& r, const nlohmann::json& check) {
  const bool fits = is_fit_quantity(check.at("quantity").get<std::string>());
  if (fits && !r.has_fits) return {describe(check) + ": this run wrote no modulus fits"};
  const auto picked = select(r, fits, check.at("at"));
  // `minus` or `plus`: the value at the paired index of a second selector is subtracted/added.
  const char* other = check.contains("minus") ? "minus" : (check.contains("plus") ? "plus" : "");
  const double sign = std::string(other) == "plus" ? 1.0 : -1.0;
  std::vector<std::size_t> base;
  if (*other != '\0') base = select(r, fits, check[other]);
  if (picked.empty()) return {describe(check) + ": the selector picks nothing"};
  if (*other != '\0' && base.size() != picked.size()) {
    return {describe(check) + ": 'at' and '" + other + "' pick different numbers of entries"};
  }
  if (!check.contains("min") && !check.contains("max") && !check.contains("equals")) {
    throw std::runtime_error(describe(check) + ": no min, max or equals");
  }
  std::vector<std::string> failures;
  for (std::size_t k = 0; k < picked.size(); ++k) {
    double v = quantity(r, check, picked[k]);
    if (!base.empty()) v += sign * quantity(r, check, base[k]);
    const bool ok = (!check.contains("min") || v >= check["min"].get<double>()) &&
                    (!check.contains("max") || v <= check["max"].get<double>()) &&
                    (!check.contains("equals") || v == check["equals"].get<double>());
    if (!ok) {
      std::ostringstream msg;
      msg.precision(6);
      msg << describe(check) << ": index " << picked[k] << " gives " << v << ", allowed "
          << (check.contains("equals")
                  ? "== " + check["equals"].dump()
                  : "[" + check.value("min", nlohmann::json("-inf")).dump() + ", " +
                        check.value("max", nlohmann::json("inf")).dump() + "]");
      failures.push_back(msg.str());
    }
  }
  return failures;
}

}  // namespace mresim::testing::promises
