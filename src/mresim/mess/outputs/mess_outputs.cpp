#include "mresim/mess/outputs/mess_outputs.hpp"

#include <fmt/format.h>

#include <cmath>
#include <limits>
#include <map>
#include <numbers>

#include "mresim/io/csv_writer.hpp"
#include "mresim/mess/outputs/analysis_outputs.hpp"
#include "mresim/mess/outputs/h5md_outputs.hpp"
#include "mresim/mess/outputs/step_extras.hpp"
#include "mresim/mess/outputs/step_records_io.hpp"
#include "mresim/mess/outputs/xdmf_outputs.hpp"
#include "mresim/mess/protocols/protocol.hpp"
#include "mresim/mess/protocols/step_plan.hpp"

namespace mresim::mess_protocol {

namespace fs = std::filesystem;
namespace mc = mresim::mess_config;

namespace {
// Rows per chunk of a step's node positions: 32,768 x 3 doubles = 768 KiB, under HDF5's
// default 1 MiB chunk cache, so a chunk is compressed in one piece; a lattice of up to 32,768
// nodes is one chunk.
constexpr std::size_t kPositionChunkRows = 32768;
}  // namespace

fs::path step_positions_file(const fs::path& run_dir, std::size_t step) {
  return run_dir / "positions" / fmt::format("step_{:06d}.h5", step);
}

void write_step_positions(const fs::path& run_dir, std::size_t step,
                          const Eigen::Matrix3Xd& positions, const Eigen::Matrix3Xd& initial) {
  const fs::path file = step_positions_file(run_dir, step);
  fs::create_directories(file.parent_path());
  const fs::path temporary = fs::path(file.string() + ".tmp");
  {
    io::Hdf5File out(temporary);
    // Column-major 3 x N is row-major N x 3.
    const auto rows = static_cast<std::size_t>(positions.cols());
    out.write_compressed_array(
        "/positions", {rows, 3},
        std::vector<double>(positions.data(), positions.data() + positions.size()), "m",
        kPositionChunkRows);
    const Eigen::Matrix3Xd u = positions - initial;
    out.write_compressed_array("/displacement", {rows, 3},
                               std::vector<double>(u.data(), u.data() + u.size()), "m",
                               kPositionChunkRows);
    out.close();
  }
  fs::rename(temporary, file);
}

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// VTK/XDMF hexahedron vertex order from the lattice's local order (vertex v at offset
// ((v>>1)&1, (v>>2)&1, v&1), volume_elements.hpp): (000, 100, 110, 010, 001, 101, 111, 011).
constexpr std::array<int, 8> kVtkOrder = {0, 2, 6, 4, 1, 3, 7, 5};

// Per cell: particle k when all eight nodes belong to it (the particle's voxels, as the
// particle_voxels figure draws them), else -1 (polymer). Unlike the node attribute particle_id,
// which ParaView interpolates across the cells at a particle's surface, this is sharp.
std::vector<std::int64_t> cell_material(const lattice::Lattice& lat) {
  std::vector<std::int64_t> material;
  material.reserve(lat.elements.size());
  for (const auto& e : lat.elements) {
    const std::int64_t k = lat.particle_of_node[static_cast<std::size_t>(e[0])];
    bool all = k >= 0;
    for (const auto node : e) {
      all = all && lat.particle_of_node[static_cast<std::size_t>(node)] == k;
    }
    material.push_back(all ? k : -1);
  }
  return material;
}

void write_lattice(io::Hdf5File& results, const ProtocolRunner& runner) {
  const lattice::Lattice& lat = runner.system().lattice();
  results.write_number_attribute("/lattice", "element_length", lat.element_length);
  results.write_number_attribute("/lattice", "particle_radius", lat.particle_radius);
  results.write_string_attribute("/lattice", "profile", std::string(runner.spec().profile->name));
  results.write_int_attribute("/lattice", "node_count", lat.node_count());
  results.write_int_attribute("/lattice", "cell_count", lat.cell_count());
  results.write_int_vector("/lattice/shape",
                           {lat.shape.nodes[0], lat.shape.nodes[1], lat.shape.nodes[2]});
  const Eigen::Vector3d box = lat.box_lengths();
  results.write_vector("/lattice/box_lengths", {box.x(), box.y(), box.z()}, "m");
  Eigen::Matrix3Xd centres(3, static_cast<Eigen::Index>(lat.particle_count()));
  for (std::size_t p = 0; p < lat.particle_count(); ++p) {
    centres.col(static_cast<Eigen::Index>(p)) = lat.particle_centres[p];
  }
  write_columns(results, "/lattice/initial_centres", centres, "m");
  results.write_number_attribute("/lattice", "volume_fraction", lat.volume_fraction());
  // The initial lattice is always written (N x 3 doubles and N ids: about 32 B per node), so the
  // initial-configuration figures (Figs. 4.2, 4.3, 4.24) can be drawn for every run.
  write_columns(results, "/lattice/initial_positions", lat.positions, "m");
  std::vector<std::int64_t> particle_id(lat.particle_of_node.begin(), lat.particle_of_node.end());
  results.write_int_vector("/lattice/particle_id", particle_id);
  if (!runner.spec().output.node_positions) return;
  std::vector<std::int64_t> cells;
  cells.reserve(lat.elements.size() * 8);
  for (const auto& e : lat.elements) {
    for (const int v : kVtkOrder) cells.push_back(e[static_cast<std::size_t>(v)]);
  }
  results.write_int_array("/lattice/cells", {lat.elements.size(), 8}, cells);
  results.write_int_vector("/lattice/cell_material", cell_material(lat));
}

void write_summary(const fs::path& run_dir, const std::vector<StepRecord>& records,
                   const StepExtras& x, const std::vector<std::int64_t>& valid,
                   const char* load_unit, const mess::TermLabels& terms) {
  std::vector<std::string> columns = {
      "step",           "field_index", "load_index", "Bx_T",
      "By_T",           "Bz_T",        "B_along_T",  std::string("load_") + load_unit,
      "measured_strain"};
  for (const mess::TermLabel& t : terms) columns.push_back("E_" + t.name + "_J");
  for (const char* c : {"E_total_J", "energy_density_J_m3", "system_volume_m3", "M_along_Ms",
                        "min_separation_m", "pair_angle_deg", "clusters", "magnetostriction",
                        "converged", "valid", "iterations", "max_force_N", "wall_time_s"}) {
    columns.emplace_back(c);
  }
  io::CsvWriter csv(run_dir / "summary.csv", columns);
  for (std::size_t i = 0; i < records.size(); ++i) {
    const StepRecord& r = records[i];
    std::vector<double> row = {static_cast<double>(r.step.index),
                               static_cast<double>(r.step.field_index),
                               static_cast<double>(r.step.load_index),
                               r.step.field.x(),
                               r.step.field.y(),
                               r.step.field.z(),
                               x.field_projection[i],
                               r.step.load_value,
                               r.measured_strain};
    for (const mess::TermLabel& t : terms) row.push_back(energy_or_nan(r.energies, t.name));
    row.insert(row.end(),
               {r.energies.total(), x.energy_density[i], r.system_volume,
                x.magnetization_projection[i], x.separation[i],
                x.pair_angle[i] * 180.0 / std::numbers::pi, static_cast<double>(x.cluster_count[i]),
                x.magnetostriction[i], r.converged ? 1.0 : 0.0, static_cast<double>(valid[i]),
                static_cast<double>(r.iterations), r.max_force, r.wall_time});
    csv.row(row);
  }
}

}  // namespace

std::string MessResultCheck::message() const {
  std::string out;
  if (non_finite.any()) out = non_finite.message("written as NaN; see /steps/valid in results.h5");
  if (unconverged.any()) {
    if (!out.empty()) out += "; ";
    out += unconverged.message("see /steps/solver/converged and /steps/valid in results.h5");
  }
  return out;
}

namespace {

// "step 3 (B = 0.04 T, load 0.02 rad)" (the load only for protocols with one).
std::string step_place(const mc::MessSpec& spec, const StepRecord& r) {
  const double b = r.step.field.dot(field_direction(spec));
  if (!spec.protocol->has_load()) return fmt::format("step {} (B = {:.4g} T)", r.step.index, b);
  return fmt::format("step {} (B = {:.4g} T, load {:.4g} {})", r.step.index, b, r.step.load_value,
                     load_unit(spec));
}

// The non-finite quantities of a step, comma-separated ("" when all are finite).
std::string non_finite_quantities(const StepRecord& r) {
  std::vector<std::string> bad;
  bool energy = std::isfinite(r.energies.total());
  for (std::size_t k = 0; k < r.energies.size(); ++k)
    energy = energy && std::isfinite(r.energies.value(k));
  if (!energy) bad.emplace_back("energy");
  if (!std::isfinite(r.system_volume)) bad.emplace_back("system volume");
  if (!std::isfinite(r.measured_strain)) bad.emplace_back("measured strain");
  if (!r.box_strain.allFinite()) bad.emplace_back("box strain");
  if (!r.centres.allFinite()) bad.emplace_back("particle centres");
  if (!r.magnetization.allFinite()) bad.emplace_back("magnetization");
  if (!std::isfinite(r.max_force)) bad.emplace_back("max force");
  if (!std::isfinite(r.magnetization_residual)) bad.emplace_back("magnetization residual");
  std::string out;
  for (const std::string& b : bad) out += (out.empty() ? "" : ", ") + b;
  return out;
}

void nan_if_not_finite(double& v) {
  if (!std::isfinite(v)) v = kNaN;
}

}  // namespace

std::vector<std::int64_t> check_steps(const mc::MessSpec& spec,
                                      const std::vector<StepRecord>& records,
                                      MessResultCheck& check) {
  std::vector<std::int64_t> valid;
  valid.reserve(records.size());
  for (const StepRecord& r : records) {
    const std::string bad = non_finite_quantities(r);
    if (!bad.empty()) {
      check.non_finite.flag(bad, step_place(spec, r));
    } else if (!r.converged) {
      // converged relaxation, unconverged final magnetization solve (protocol_runner.cpp)
      const std::string what =
          r.status == "converged"
              ? fmt::format("final magnetization solve ({}, residual {:.3g} Ms)",
                            r.magnetization_method, r.magnetization_residual)
              : fmt::format("relaxation ({})", r.status);
      check.unconverged.flag(what, step_place(spec, r));
    }
    valid.push_back(bad.empty() && r.converged ? 1 : 0);
  }
  return valid;
}

std::vector<StepRecord> with_nan_for_non_finite(std::vector<StepRecord> records) {
  for (StepRecord& r : records) {
    for (std::size_t k = 0; k < r.energies.size(); ++k) nan_if_not_finite(r.energies.value(k));
    nan_if_not_finite(r.system_volume);
    nan_if_not_finite(r.measured_strain);
    nan_if_not_finite(r.max_force);
    nan_if_not_finite(r.magnetization_residual);
    for (double& e : r.box_strain) nan_if_not_finite(e);
    for (Eigen::Matrix3Xd* m : {&r.centres, &r.magnetization}) {
      *m = m->unaryExpr([](double v) { return std::isfinite(v) ? v : kNaN; });
    }
  }
  return records;
}

MessResultCheck write_mess_results(const fs::path& run_dir, io::Hdf5File& results,
                                   const ProtocolRunner& runner,
                                   const std::vector<StepRecord>& computed) {
  const mc::MessSpec& spec = runner.spec();
  const char* unit = load_unit(spec);
  MessResultCheck check;
  const std::vector<std::int64_t> valid = check_steps(spec, computed, check);
  const std::vector<StepRecord> records = with_nan_for_non_finite(computed);
  write_lattice(results, runner);
  const std::size_t np = runner.system().particle_count();
  write_step_records(results, "/steps", records, np, unit, *runner.system().energy_labels());
  results.write_int_vector("/steps/valid", valid);
  const Eigen::Vector3d d = field_direction(spec);
  const StepExtras x = step_extras(records, d, spec.analysis.cluster_distance, spec.particles.Ms);
  results.write_vector("/steps/field_direction", {d.x(), d.y(), d.z()}, "1");
  results.write_vector("/steps/field_projection", x.field_projection, "T");
  results.write_vector("/steps/magnetization_projection", x.magnetization_projection, "1");
  results.write_vector("/steps/energy_density", x.energy_density, "J/m^3");
  results.write_vector("/steps/separation", x.separation, "m");
  results.write_vector("/steps/pair_angle", x.pair_angle, "rad");
  results.write_string_attribute(
      "/steps/pair_angle", "reference",
      "the field direction /steps/field_direction: angle between it and the centre-to-centre "
      "vector of the closest pair, in [0, pi/2]");
  results.write_vector("/steps/magnetostriction", x.magnetostriction, "1");
  results.write_int_vector("/steps/cluster_count", x.cluster_count);
  results.write_int_vector("/steps/largest_cluster", x.largest_cluster);
  results.write_int_array("/steps/cluster_id", {records.size(), np}, x.cluster_id);
  results.write_number_attribute("/steps", "cluster_distance", spec.analysis.cluster_distance);
  write_summary(run_dir, records, x, valid, unit, *runner.system().energy_labels());
  if (spec.protocol->analysis().kind != AnalysisKind::none) {
    write_analysis(run_dir, results, runner, records, x.energy_density, check);
  }
  write_h5md(results, runner, records);
  write_xdmf_views(run_dir, runner, records, x.field_projection);
  return check;
}

}  // namespace mresim::mess_protocol
