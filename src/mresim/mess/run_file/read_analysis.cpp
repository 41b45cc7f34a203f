#include "mresim/mess/run_file/read_analysis.hpp"

#include <fmt/format.h>

#include "mresim/mess/terms/magnetic_energy.hpp"

namespace mresim::mess_config {

AnalysisSpec read_analysis(const std::optional<config::TableReader>& table,
                           double particle_radius) {
  AnalysisSpec a;
  // The WCA cut-off does not depend on the energy scale (eq. 4.79: r_cut = 2^(1/6) r_min,
  // r_min = 2R + 100 nm); the scale passed is irrelevant here.
  a.cluster_distance = magnetism::WcaParameters::from_radius(particle_radius, 1.0).r_cut();
  if (!table) return a;
  const double contact = 2.0 * particle_radius;
  // Finite first (the reader's own message for nan and inf), then the radius-dependent bound.
  const auto given = table->optional_number("cluster_distance", config::Range::positive(), "m");
  if (!given) return a;
  if (!(*given >= contact)) {
    table->fail("cluster_distance", table->value_text("cluster_distance"),
                fmt::format("must be >= 2R = {:.6g} m (touching spheres) and finite; the default "
                            "is the WCA cut-off 2^(1/6)(2R + 100 nm) = {:.6g} m",
                            contact, a.cluster_distance));
  }
  a.cluster_distance = *given;
  a.cluster_distance_given = true;
  return a;
}

}  // namespace mresim::mess_config
