// `mresim info` for the 3D run types: everything the run file implies, from closed forms and the
// placed particles (MessGeometry), without building springs or relaxing anything.

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "mresim/core/constants.hpp"
#include "mresim/mess/protocols/protocol.hpp"
#include "mresim/mess/run_file/mess_spec.hpp"
#include "mresim/mess/solvers/minimiser.hpp"

namespace mresim::mess_config {

namespace {

// Centres listed one by one up to this many particles; the closest pair is searched up to
// kClosestPairLimit particles (O(N^2)).
constexpr std::size_t kCentresShown = 64;
constexpr std::size_t kClosestPairLimit = 4000;

std::string with_thousands(std::int64_t n) {
  std::string digits = fmt::format("{}", n < 0 ? -n : n);
  std::string out;
  for (std::size_t i = 0; i < digits.size(); ++i) {
    if (i > 0 && (digits.size() - i) % 3 == 0) out += ',';
    out += digits[i];
  }
  return n < 0 ? "-" + out : out;
}

std::string placement_name(const MessSpec& s) { return lattice::to_string(s.placement_kind); }

void describe_lattice(const MessSpec& s, app::InfoReport& r) {
  const MessGeometry& g = s.geometry;
  const std::string sec = "lattice";
  r.add(sec, "element_length", g.element_length, "m", "l_e = 2R/(2 n_d + 1), eq. 4.49");
  r.add_text(sec, "grid", fmt::format("{} x {} x {}", g.shape.nx(), g.shape.ny(), g.shape.nz()),
             "nodes along x, y, z");
  r.add_integer(sec, "nodes", g.node_count());
  r.add_integer(sec, "cells", g.cell_count(), "", "volume elements");
  r.add(sec, "box_length_x", g.box_lengths[0], "m", "(N_x - 1) l_e");
  r.add(sec, "box_length_y", g.box_lengths[1], "m");
  r.add(sec, "box_length_z", g.box_lengths[2], "m");
  r.add(sec, "box_volume", g.box_lengths.prod(), "m^3");
  if (s.box) {
    r.add_text(sec, "box_rounding",
               s.box->rounding == lattice::BoxRounding::nearest ? "nearest" : "seed_floor_divide",
               s.box->rounding == lattice::BoxRounding::nearest
                   ? "N = round(L/l_e + 1)"
                   : "N = (L // l_e) + 1, the original's by-hand rule");
  }
  const lattice::SpringCounts& c = g.springs;
  const ParticleSpringCounts& p = g.particle_springs;
  r.add_integer(sec, "springs", c.total(), "", "closed forms (docs/lattice.md)");
  r.add_integer(sec, "edge_springs", c.edge.total(), "",
                fmt::format("{} at k_e/4, {} at k_e/2, {} with the particle constant",
                            with_thousands(c.edge.quarter), with_thousands(c.edge.half),
                            with_thousands(p.edge)));
  r.add_integer(sec, "face_springs", c.face.total(), "",
                fmt::format("{} at k_f/2, {} with the particle constant",
                            with_thousands(c.face.half), with_thousands(p.face)));
  r.add_integer(sec, "body_springs", c.body.total(), "",
                fmt::format("{} with the particle constant", with_thousands(p.body)));
  r.add_integer(sec, "particle_springs", p.total(), "",
                s.lattice.particle_spring_rule == lattice::ParticleSpringRule::same_particle
                    ? "both ends in the same particle"
                    : "both ends particle nodes of any particles (as the original code)");
}

void describe_stiffness(const MessSpec& s, app::InfoReport& r) {
  const lattice::LatticeSpec& l = s.lattice;
  const double l_e = s.geometry.element_length;
  const std::string sec = "stiffness";
  const lattice::LatticeStiffness k = lattice::polymer_stiffness(
      l.shear_modulus_rule, l.youngs_modulus, l.poisson_ratio, l_e, l.stiffness_ratio);
  const lattice::LatticeModuli m = lattice::lattice_moduli(k, l_e);
  const bool exact_moduli =
      l.shear_modulus_rule == lattice::ShearModulusRule::from_youngs_and_poisson;
  r.add_text(sec, "profile", std::string(s.profile->name),
             std::string(s.profile->shear_modulus_note));
  r.add(sec, "youngs_modulus", l.youngs_modulus, "Pa", "polymer E, as given");
  r.add(sec, "poisson_ratio", l.poisson_ratio, "", "polymer nu, as given");
  r.add(sec, "stiffness_ratio", l.stiffness_ratio, "", "A = k_f/k_c");
  r.add(sec, "k_e", k.springs.edge, "N/m", "edge springs, bulk value");
  r.add(sec, "k_f", k.springs.face, "N/m", "face diagonals, bulk value");
  r.add(sec, "k_c", k.springs.body, "N/m", "body diagonals");
  r.add(sec, "kappa", k.kappa, "Pa", "extra bulk modulus, eq. 4.22");
  r.add(sec, "lattice_shear_modulus", m.shear_modulus, "Pa",
        exact_moduli ? "= E/(2(1+nu))" : "= 0.4 E (nu-independent, as the original code)");
  r.add(sec, "lattice_bulk_modulus", m.bulk_modulus, "Pa", "kappa + 5G/3, eq. 4.21");
  r.add(sec, "lattice_youngs_modulus", m.youngs_modulus, "Pa", "particle-free, uniaxial stress");
  r.add(sec, "lattice_poisson_ratio", m.poisson_ratio, "", "particle-free, uniaxial stress");
  const lattice::SpringConstants kp = lattice::particle_spring_constants(
      l.shear_modulus_rule, l.youngs_modulus, l.poisson_ratio, l_e, l.stiffness_ratio);
  r.add(sec, "particle_youngs_modulus", lattice::particle_youngs_modulus(l.youngs_modulus), "Pa",
        "E_p = min(2.11e11 Pa, 1e4 E)");
  r.add(sec, "particle_k_e", kp.edge, "N/m");
  r.add(sec, "particle_k_f", kp.face, "N/m");
  r.add(sec, "particle_k_c", kp.body, "N/m");
}

void describe_scales(const MessSpec& s, app::InfoReport& r) {
  const lattice::LatticeSpec& l = s.lattice;
  const double l_e = s.geometry.element_length;
  const std::string sec = "scales";
  const lattice::LatticeStiffness k = lattice::polymer_stiffness(
      l.shear_modulus_rule, l.youngs_modulus, l.poisson_ratio, l_e, l.stiffness_ratio);
  const double m_c = l.polymer_density * l_e * l_e * l_e;
  const double k_eff = lattice::effective_spring_constant(k.springs);
  const double t_c = 2.0 * std::numbers::pi * std::sqrt(m_c / k_eff);
  r.add(sec, "length", l_e, "m", "x_c = l_e");
  r.add(sec, "mass", m_c, "kg", "m_c = rho_polymer l_e^3 (an interior polymer node)");
  r.add(sec, "k_eff", k_eff, "N/m", "2 k_e + 8 k_f/sqrt(2) + 4 k_c");
  r.add(sec, "time", t_c, "s", "t_c = 2 pi sqrt(m_c/k_eff)");
  r.add(sec, "force", k_eff * l_e, "N", "k_eff l_e");
  const double particle_mass = l.iron_density * lattice::sphere_volume(l.particle_radius);
  r.add(sec, "particle_mass", particle_mass, "kg", "rho_iron 4/3 pi R^3, eq. 4.53");
  r.add(sec, "particle_node_mass",
        particle_mass / static_cast<double>(s.geometry.nodes_per_particle), "kg",
        fmt::format("{:.3g} m_c",
                    particle_mass / static_cast<double>(s.geometry.nodes_per_particle) / m_c));
}

void describe_particles(const MessSpec& s, app::InfoReport& r) {
  const MessGeometry& g = s.geometry;
  const std::string sec = "particles";
  const magnetism::MagneticParticles& p = s.particles;
  r.add_integer(sec, "count", static_cast<std::int64_t>(g.particle_count()));
  r.add_text(sec, "placement", placement_name(s));
  if (s.requested_volume_fraction) {
    r.add(sec, "requested_volume_fraction", *s.requested_volume_fraction, "");
  }
  r.add(sec, "volume_fraction", g.volume_fraction, "",
        "N V_p / (L_x L_y L_z) of the lattice, eq. 4.50");
  r.add(sec, "radius", p.radius, "m");
  r.add(sec, "volume", p.volume(), "m^3", "V_p = 4/3 pi R^3");
  r.add_integer(sec, "discretization_order", s.lattice.discretization_order, "",
                fmt::format("n_d: {} voxels across", 2 * s.lattice.discretization_order + 1));
  r.add_integer(sec, "nodes_per_particle", g.nodes_per_particle);
  r.add(sec, "saturation_magnetization", p.Ms, "A/m");
  r.add(sec, "susceptibility", p.chi0, "", "chi0 of the Froehlich-Kennelly law, eq. 4.55");
  r.add_text(sec, "demagnetization", s.demagnetization ? "on" : "off",
             s.demagnetization ? "FK law applied to H_local - M/3" : "the dissertation's law");
  r.add_text(sec, "self_energy",
             s.self_energy == magnetism::SelfEnergyForm::consistent ? "consistent" : "linearized",
             s.self_energy == magnetism::SelfEnergyForm::consistent
                 ? "eq. 4.76, consistent with the dipole forces"
                 : "eq. 4.73, the dissertation's energy plots");
  const magnetism::WcaParameters wca =
      magnetism::WcaParameters::from_radius(p.radius, s.profile->wca_scale_ms(p.Ms));
  r.add(sec, "wca_energy", wca.e_max, "J",
        s.profile->wca_ms ? fmt::format("mu0 pi Ms^2 R^3/72 with Ms = {:g} A/m ({} profile)",
                                        *s.profile->wca_ms, s.profile->name)
                          : "mu0 pi Ms^2 R^3/72, eq. 4.79");
  r.add(sec, "wca_r_min", wca.r_min, "m", "2R + 100 nm");
  r.add(sec, "cluster_distance", s.analysis.cluster_distance, "m",
        s.analysis.cluster_distance_given
            ? "[analysis] cluster_distance: centres this close are in contact"
            : "the WCA cut-off 2^(1/6)(2R + 100 nm) (default): centres this close are in contact");
  if (!s.demagnetization) {
    r.add(sec, "zero_field_instability_distance", p.radius * std::cbrt(2.0 * p.chi0 / 3.0), "m",
          "pairs along the field closer than R (2 chi0/3)^(1/3) keep a remanent M at B = 0");
  }
  const std::size_t n = g.particle_count();
  if (n >= 2 && n <= kClosestPairLimit) {
    double closest = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < n; ++i) {
      for (std::size_t j = i + 1; j < n; ++j) {
        closest = std::min(closest, (g.particle_centres[i] - g.particle_centres[j]).norm());
      }
    }
    r.add(sec, "closest_centre_distance", closest, "m",
          fmt::format("{:.4g} R; contact at 2R", closest / p.radius));
  }
  for (std::size_t i = 0; i < n && i < kCentresShown; ++i) {
    const Eigen::Vector3d& x = g.particle_centres[i];
    const auto& c = g.centre_cells[i];
    r.add_text(sec, fmt::format("centre_{}", i),
               fmt::format("({:.6g}, {:.6g}, {:.6g}) m", x[0], x[1], x[2]),
               fmt::format("({}.5, {}.5, {}.5) l_e", c[0], c[1], c[2]));
  }
  if (n > kCentresShown) {
    r.add_text(sec, "centres_not_shown", fmt::format("{}", n - kCentresShown),
               "only the first 64 centres are listed");
  }
}

void describe_field(const MessSpec& s, app::InfoReport& r) {
  const FieldSpec& f = s.field;
  const std::string sec = "field";
  switch (f.form) {
    case FieldSpec::Form::max_and_steps:
      r.add_text(sec, "given_as", "max and steps");
      r.add(sec, "max", f.max, "T", "B_ext = mu0 H_ext");
      r.add_integer(sec, "increments", f.steps, "",
                    fmt::format("step {:.6g} T", f.max / static_cast<double>(f.steps)));
      break;
    case FieldSpec::Form::magnitudes:
      r.add_text(sec, "given_as", "magnitudes");
      r.add(sec, "max", f.max, "T", "B_ext = mu0 H_ext");
      r.add_integer(sec, "magnitudes", static_cast<std::int64_t>(f.magnitudes.size()));
      break;
    case FieldSpec::Form::vectors:
      r.add_text(sec, "given_as", "vectors");
      r.add(sec, "max", f.max, "T", "largest |B_ext|");
      break;
  }
  if (f.form != FieldSpec::Form::vectors) {
    r.add(sec, "theta", f.theta_deg, "deg", "polar angle from +z");
    r.add(sec, "phi", f.phi_deg, "deg", "azimuth from +x");
    const Eigen::Vector3d u = field_vector(1.0, f.theta_deg, f.phi_deg);
    r.add_text(sec, "direction", fmt::format("({:.6g}, {:.6g}, {:.6g})", u[0], u[1], u[2]));
    r.add_text(
        sec, "sequence", f.sequence == FieldSequence::loop ? "loop" : "up",
        f.sequence == FieldSequence::loop ? "0 -> max -> -max -> max" : "the magnitudes in order");
  }
  r.add_integer(sec, "fields", static_cast<std::int64_t>(f.values.size()),
                s.protocol->has_load() ? "applied at every load value" : "relaxations");
  r.add(sec, "max_reduced_field", f.max / (kMu0 * s.particles.Ms), "", "h = B/(mu0 Ms)");
}

// Which named tolerance atol and rtol are (docs/magnetization-3d.md), or that they were set.
std::string magnetization_tolerance_name(const magnetism::MagnetizationOptions& m) {
  using O = magnetism::MagnetizationOptions;
  if (m.atol == O::kTightAtol && m.rtol == O::kTightRtol) {
    return "tight";
  }
  if (m.atol == O::kOriginalAtol && m.rtol == O::kOriginalRtol) {
    return "original";
  }
  return "custom";
}

void describe_solver(const MessSpec& s, app::InfoReport& r) {
  const SolverSpec& v = s.solver;
  const std::string sec = "solver";
  if (v.method != SolverMethod::leapfrog) {
    r.add_text(sec, "method", solver_method_name(v.method),
               v.method == SolverMethod::newton ? "Newton-Krylov with algebraic multigrid"
               : v.method == SolverMethod::lbfgs
                   ? "L-BFGS, rigid-particle preconditioner"
                   : "L-BFGS, multilevel preconditioner from 40,000 nodes");
    r.add(sec, "force_tolerance", v.minimiser.force_tolerance, "k_eff l_e",
          "largest net force on a free node");
    r.add_integer(sec, "max_iterations", v.minimiser.max_iterations);
    if (v.method == SolverMethod::minimiser) {
      const bool blocks = v.node_scaling == mess::NodeScaling::blocks;
      r.add_text(sec, "node_scaling", blocks ? "blocks" : "diagonal",
                 blocks ? "the multilevel preconditioner inverts each polymer node's 3 x 3 "
                          "stiffness block"
                        : "the multilevel preconditioner inverts each node's diagonal (before "
                          "the blocks)");
      const bool gap = v.contact_gap == mess::ContactGap::exact;
      r.add_text(sec, "contact_gap", gap ? "exact" : "none",
                 gap ? "the multilevel preconditioner solves the polymer between particles in "
                       "contact exactly"
                     : "the polymer between particles in contact is left to the node scaling "
                       "(before the gap blocks)");
      r.add(sec, "preconditioner_reuse", v.preconditioner_reuse, "l_e",
            v.preconditioner_reuse > 0.0
                ? "a step keeps the multilevel preconditioner of an earlier step's start while "
                  "no node has moved further and the same particles are in contact"
                : "the multilevel preconditioner is built at every step's start");
    }
  } else {
    const lattice::LatticeSpec& l = s.lattice;
    const double l_e = s.geometry.element_length;
    const lattice::LatticeStiffness k = lattice::polymer_stiffness(
        l.shear_modulus_rule, l.youngs_modulus, l.poisson_ratio, l_e, l.stiffness_ratio);
    const double k_eff = lattice::effective_spring_constant(k.springs);
    const double t_c =
        2.0 * std::numbers::pi * std::sqrt(l.polymer_density * l_e * l_e * l_e / k_eff);
    r.add_text(sec, "method", "leapfrog", "the seed's damped dynamics (reference)");
    std::string note = fmt::format("{:.6g} s", v.leapfrog.dt * t_c);
    if (const auto limit = leapfrog_stability_limit(l.discretization_order)) {
      note += fmt::format("; seed stability limit about {:.2g} for n_d = {}", *limit,
                          l.discretization_order);
      if (v.leapfrog.dt >= *limit) note += " - EXCEEDED, expect blow-up";
    }
    r.add(sec, "dt", v.leapfrog.dt, "t_c", note);
    r.add_integer(sec, "steps_per_round", v.leapfrog.steps_per_round);
    r.add_integer(sec, "max_rounds", v.leapfrog.max_rounds);
    r.add(sec, "drag", v.leapfrog.drag, "1/t_c");
  }
  if (s.protocol->loads_from_zero_load_state()) {
    switch (v.load_step_start) {
      case LoadStepStart::extrapolated:
        r.add_text(sec, "load_step_start", "extrapolated",
                   "each strain starts from a prediction (the strain secant, or the previous "
                   "field's response), corrected by the previous fields' misses of theirs");
        break;
      case LoadStepStart::secant:
        r.add_text(sec, "load_step_start", "secant",
                   "each strain starts from the strain secant, or the previous field's "
                   "response, uncorrected");
        break;
      case LoadStepStart::previous:
        r.add_text(sec, "load_step_start", "previous",
                   "each strain starts from the previous one's state (the original)");
        break;
    }
  }
  const bool field_extrapolated = v.field_step_start == FieldStepStart::extrapolated;
  r.add_text(sec, "field_step_start", field_extrapolated ? "extrapolated" : "previous",
             field_extrapolated
                 ? "each field from the third on starts from the secant through the two "
                   "previous fields' results"
                 : "each field starts from the previous field's result (the original)");
  const magnetism::MagnetizationOptions& m = v.magnetization;
  const std::string tolerance = magnetization_tolerance_name(m);
  r.add_text(sec, "magnetization_tolerance", tolerance,
             tolerance == "tight"      ? "M self-consistent to near machine precision"
             : tolerance == "original" ? "the original code's loose band: M lags the positions"
                                       : "atol and rtol as set");
  r.add(sec, "magnetization_atol", m.atol, "Ms");
  r.add(sec, "magnetization_rtol", m.rtol, "");
  r.add_text(sec, "magnetization_iterations",
             fmt::format("{} fixed point, {} Anderson, {} Newton", m.max_fixed_point_iterations,
                         m.max_anderson_iterations, m.max_newton_iterations),
             "per method of the fallback chain");
  r.add_text(sec, "magnetization_check_stability", m.check_stability ? "on" : "off");
}

// The estimate a run is checked against (check_memory), and the memory available now.
void describe_memory(const MessSpec& s, app::InfoReport& r) {
  constexpr double kMiB = 1 << 20;
  r.add("memory", "estimate", static_cast<double>(estimated_memory_bytes(s)) / kMiB, "MiB",
        fmt::format("{:.0f} MiB + {} bytes per node + 32 (3N)^2 bytes for N particles",
                    static_cast<double>(kFixedBytes) / kMiB, bytes_per_node(s)));
  if (scratch_bytes_per_node(s) > 0) {
    r.add("memory", "scratch_disk",
          static_cast<double>(scratch_bytes_per_node(s) * s.geometry.node_count()) / kMiB, "MiB",
          fmt::format("{} bytes per node at most: the {} fields' latest and zero-load states{}, "
                      "kept in an unnamed scratch file beside the results while other fields run",
                      scratch_bytes_per_node(s), s.field.values.size(),
                      s.keeps_earlier_load_results()
                          ? ", their results at the strain before and the strain secants' misses"
                          : ""));
  }
  const AvailableMemory available = available_memory();
  if (available.bytes) {
    r.add("memory", "available", static_cast<double>(*available.bytes) / kMiB, "MiB",
          available.source + "; a run needing more is refused");
  } else {
    r.add_text("memory", "available", "unknown", "no check");
  }
}

}  // namespace

void describe_mess(const MessSpec& s, app::InfoReport& r) {
  r.add_text("mess", "run_type", s.run_type);
  r.add_integer("mess", "relaxations", static_cast<std::int64_t>(s.relaxation_count()), "",
                s.load_step_count() > 1 ? fmt::format("{} fields x {} load values",
                                                      s.field.values.size(), s.load_step_count())
                                        : "one per field");
  describe_lattice(s, r);
  describe_memory(s, r);
  describe_stiffness(s, r);
  describe_scales(s, r);
  describe_particles(s, r);
  describe_field(s, r);
  s.protocol->describe(s, r);  // the protocol's own table, e.g. [strain]
  describe_solver(s, r);
  r.add_text("output", "node_positions", s.output.node_positions ? "on" : "off",
             s.output.node_positions
                 ? fmt::format("{:.3g} MB per step (float64)",
                               24.0 * static_cast<double>(s.geometry.node_count()) / 1e6)
                 : "");
  r.add_integer("output", "checkpoint_every", s.output.checkpoint_every, "steps",
                s.output.checkpoint_every == 0 ? "no checkpoints" : "");
  // final_state.h5: the positions of every slot (one per field with a load) and the zero-load
  // references, float64 (restart/saved_run.hpp); with one slot and predicted field steps also
  // the result before the last (ProtocolState::earlier_field_result), with a slot per field and
  // predicted strain steps each field's result at the load value before its slot's
  // (ProtocolState::earlier_load_results); where the multilevel
  // preconditioner is kept between steps, the positions it was built at (its anchor).
  const bool earlier_result = s.keeps_earlier_field_result();
  const bool anchor = s.solver.method == SolverMethod::minimiser &&
                      s.solver.preconditioner_reuse > 0.0 &&
                      s.geometry.node_count() >= mess::kMultilevelMinimumNodes;
  const double per_field = s.keeps_earlier_load_results() ? 3.0 : 2.0;
  const double slots =
      (s.load_step_count() > 1 ? per_field * static_cast<double>(s.field.values.size())
                               : (earlier_result ? 2.0 : 1.0)) +
      (anchor ? 1.0 : 0.0);
  r.add_text("output", "keep_final_state", s.output.keep_final_state ? "on" : "off",
             s.output.keep_final_state
                 ? fmt::format("final_state.h5 of {:.3g} MB, for mresim extend and rerun",
                               24.0 * slots * static_cast<double>(s.geometry.node_count()) / 1e6)
                 : "");
  for (std::size_t i = 0; i < s.warnings.size(); ++i) {
    r.add_text("warnings", fmt::format("warning_{}", i), s.warnings[i]);
  }
}

}  // namespace mresim::mess_config
