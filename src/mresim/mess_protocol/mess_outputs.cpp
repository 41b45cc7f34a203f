#include "mresim/mess_protocol/mess_outputs.hpp"

#include <fmt/format.h>

#include <cmath>
#include <fstream>
#include <limits>
#include <map>

#include "mresim/io/csv_writer.hpp"
#include "mresim/mess_analysis/clusters.hpp"
#include "mresim/mess_analysis/modulus_fit.hpp"
#include "mresim/mess_protocol/step_plan.hpp"
#include "mresim/mess_protocol/step_records_io.hpp"

namespace mresim::mess_protocol {

namespace fs = std::filesystem;
namespace mc = mresim::mess_config;
namespace ma = mresim::mess_analysis;

fs::path step_positions_file(const fs::path& run_dir, std::size_t step) {
  return run_dir / "positions" / fmt::format("step_{:06d}.h5", step);
}

void write_step_positions(const fs::path& run_dir, std::size_t step,
                          const Eigen::Matrix3Xd& positions) {
  const fs::path file = step_positions_file(run_dir, step);
  fs::create_directories(file.parent_path());
  const fs::path temporary = fs::path(file.string() + ".tmp");
  {
    io::Hdf5File out(temporary);
    write_columns(out, "/positions", positions, "m");
    out.close();
  }
  fs::rename(temporary, file);
}

namespace {

// VTK/XDMF hexahedron vertex order from the lattice's local order (vertex v at offset
// ((v>>1)&1, (v>>2)&1, v&1), volume_elements.hpp): (000, 100, 110, 010, 001, 101, 111, 011).
constexpr std::array<int, 8> kVtkOrder = {0, 2, 6, 4, 1, 3, 7, 5};

void write_lattice(io::Hdf5File& results, const ProtocolRunner& runner) {
  const lattice::Lattice& lat = runner.system().lattice();
  results.write_number_attribute("/lattice", "element_length", lat.element_length);
  results.write_number_attribute("/lattice", "particle_radius", lat.particle_radius);
  results.write_string_attribute("/lattice", "profile", to_string(lat.profile));
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
  if (!runner.spec().output.node_positions) return;
  write_columns(results, "/lattice/initial_positions", lat.positions, "m");
  std::vector<std::int64_t> cells;
  cells.reserve(lat.elements.size() * 8);
  for (const auto& e : lat.elements) {
    for (const int v : kVtkOrder) cells.push_back(e[static_cast<std::size_t>(v)]);
  }
  results.write_int_array("/lattice/cells", {lat.elements.size(), 8}, cells);
  std::vector<std::int64_t> particle_id(lat.particle_of_node.begin(), lat.particle_of_node.end());
  results.write_int_vector("/lattice/particle_id", particle_id);
}

struct StepExtras {
  std::vector<double> field_projection;
  std::vector<double> magnetization_projection;
  std::vector<double> energy_density;
  std::vector<double> separation;
  std::vector<std::int64_t> cluster_count;
  std::vector<std::int64_t> largest_cluster;
  std::vector<std::int64_t> cluster_id;  // steps x particles
};

StepExtras step_extras(const ProtocolRunner& runner, const std::vector<StepRecord>& records) {
  const Eigen::Vector3d d = field_direction(runner.spec());
  const double ms = runner.spec().particles.Ms;
  const double contact = runner.system().model().wca.r_cut() > 0.0
                             ? runner.system().model().wca.r_cut()
                             : 2.0 * runner.system().lattice().particle_radius;
  StepExtras x;
  for (const StepRecord& r : records) {
    x.field_projection.push_back(r.step.field.dot(d));
    const auto np = r.magnetization.cols();
    x.magnetization_projection.push_back(np > 0 ? (d.transpose() * r.magnetization).mean() / ms
                                                : 0.0);
    x.energy_density.push_back(r.energies.total() / r.system_volume);
    x.separation.push_back(ma::min_separation(r.centres));
    const ma::Clusters c = ma::find_clusters(r.centres, contact);
    x.cluster_count.push_back(c.count);
    x.largest_cluster.push_back(c.largest);
    x.cluster_id.insert(x.cluster_id.end(), c.id.begin(), c.id.end());
  }
  return x;
}

std::string modulus_name(const mc::MessSpec& spec) {
  const mc::LoadKind kind = spec.strain ? spec.strain->kind : spec.stress->kind;
  if (kind == mc::LoadKind::shear) return "G_eff";
  if (kind == mc::LoadKind::torsion) return "torsion_stiffness";
  return "E_eff";
}

// Per field: the modulus from the steps at that field (Section 4.2.8).
void write_analysis(const fs::path& run_dir, io::Hdf5File& results, const ProtocolRunner& runner,
                    const std::vector<StepRecord>& records, const StepExtras& extras) {
  const mc::MessSpec& spec = runner.spec();
  const std::size_t fields = spec.field.values.size();
  std::vector<double> magnitude;
  std::vector<double> modulus;
  std::vector<double> offset;
  std::vector<double> rms;
  std::vector<double> mr;
  std::vector<std::int64_t> first;
  std::vector<std::int64_t> points;
  std::vector<std::int64_t> split;
  for (std::size_t f = 0; f < fields; ++f) {
    std::vector<double> strain;
    std::vector<double> density;
    std::vector<double> stress;
    for (std::size_t i = 0; i < records.size(); ++i) {
      if (records[i].step.field_index != f) continue;
      strain.push_back(records[i].measured_strain);
      density.push_back(extras.energy_density[i]);
      stress.push_back(records[i].step.load_value);
    }
    magnitude.push_back(spec.field.values[f].norm());
    if (spec.strain) {
      const ma::QuadraticFit fit = ma::fit_energy_density(strain, density);
      modulus.push_back(fit.valid ? fit.modulus : std::numeric_limits<double>::quiet_NaN());
      offset.push_back(fit.offset);
      rms.push_back(fit.rms_residual);
      first.push_back(static_cast<std::int64_t>(fit.first));
      points.push_back(static_cast<std::int64_t>(fit.points));
      split.push_back(fit.split ? 1 : 0);
    } else {
      first.push_back(0);
      const ma::LinearFit fit = ma::fit_stress_strain(strain, stress);
      modulus.push_back(fit.valid ? fit.modulus : std::numeric_limits<double>::quiet_NaN());
      offset.push_back(0.0);
      rms.push_back(fit.rms_residual);
      points.push_back(static_cast<std::int64_t>(fit.points));
      split.push_back(0);
    }
  }
  for (const double m : modulus) mr.push_back(ma::mr_effect_percent(m, modulus.front()));

  const std::string name = modulus_name(spec);
  const char* unit = name == "torsion_stiffness" ? "J/m^3" : "Pa";
  results.write_string_attribute("/analysis", "modulus_name", name);
  results.write_string_attribute("/analysis", "method",
                                 spec.strain ? "energy density = a x^2/2 + c, least squares"
                                             : "stress = a x, least squares through 0");
  results.write_vector("/analysis/field_magnitude", magnitude, "T");
  results.write_vector("/analysis/modulus", modulus, unit);
  results.write_vector("/analysis/offset", offset, "J/m^3");
  results.write_vector("/analysis/rms_residual", rms, spec.strain ? "J/m^3" : "Pa");
  results.write_int_vector("/analysis/first_point", first);
  results.write_int_vector("/analysis/fit_points", points);
  results.write_int_vector("/analysis/split", split);
  results.write_vector("/analysis/mr_effect", mr, "%");

  io::CsvWriter csv(
      run_dir / "modulus.csv",
      {"field_index", "B_T", name + (name == "torsion_stiffness" ? "_J_m3" : "_Pa"), "offset_J_m3",
       "rms_residual", "first_point", "fit_points", "mr_effect_percent"});
  for (std::size_t f = 0; f < fields; ++f) {
    csv.row({static_cast<double>(f), magnitude[f], modulus[f], offset[f], rms[f],
             static_cast<double>(first[f]), static_cast<double>(points[f]), mr[f]});
  }
}

void write_summary(const fs::path& run_dir, const std::vector<StepRecord>& records,
                   const StepExtras& x, const char* load_unit) {
  std::vector<std::string> columns = {
      "step",           "field_index", "load_index", "Bx_T",
      "By_T",           "Bz_T",        "B_along_T",  std::string("load_") + load_unit,
      "measured_strain"};
  for (const EnergyTerm& t : energy_terms()) columns.push_back(std::string("E_") + t.name + "_J");
  for (const char* c :
       {"E_total_J", "energy_density_J_m3", "system_volume_m3", "M_along_Ms", "min_separation_m",
        "clusters", "converged", "iterations", "max_force_N", "wall_time_s"}) {
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
    for (const EnergyTerm& t : energy_terms()) row.push_back(r.energies.*(t.member));
    row.insert(row.end(), {r.energies.total(), x.energy_density[i], r.system_volume,
                           x.magnetization_projection[i], x.separation[i],
                           static_cast<double>(x.cluster_count[i]), r.converged ? 1.0 : 0.0,
                           static_cast<double>(r.iterations), r.max_force, r.wall_time});
    csv.row(row);
  }
}

// ParaView reads the deformed lattice of every step through this XDMF 3 file.
void write_xdmf(const fs::path& run_dir, const ProtocolRunner& runner,
                const std::vector<StepRecord>& records) {
  const lattice::Lattice& lat = runner.system().lattice();
  const auto nodes = lat.node_count();
  const auto cells = lat.cell_count();
  std::ofstream out(run_dir / "mess.xdmf");
  out << "<?xml version=\"1.0\" ?>\n<Xdmf Version=\"3.0\">\n <Domain>\n"
      << "  <Grid Name=\"steps\" GridType=\"Collection\" CollectionType=\"Temporal\">\n";
  for (const StepRecord& r : records) {
    const std::size_t s = r.step.index;
    out << fmt::format("   <Grid Name=\"step_{}\" GridType=\"Uniform\">\n", s)
        << fmt::format("    <Time Value=\"{}\"/>\n", s)
        << fmt::format("    <Topology TopologyType=\"Hexahedron\" NumberOfElements=\"{}\">\n",
                       cells)
        << fmt::format(
               "     <DataItem Dimensions=\"{} 8\" NumberType=\"Int\" Precision=\"8\" "
               "Format=\"HDF\">results.h5:/lattice/cells</DataItem>\n",
               cells)
        << "    </Topology>\n    <Geometry GeometryType=\"XYZ\">\n"
        << fmt::format(
               "     <DataItem Dimensions=\"{} 3\" NumberType=\"Float\" Precision=\"8\" "
               "Format=\"HDF\">positions/step_{:06d}.h5:/positions</DataItem>\n",
               nodes, s)
        << "    </Geometry>\n"
        << "    <Attribute Name=\"particle_id\" AttributeType=\"Scalar\" Center=\"Node\">\n"
        << fmt::format(
               "     <DataItem Dimensions=\"{}\" NumberType=\"Int\" Precision=\"8\" "
               "Format=\"HDF\">results.h5:/lattice/particle_id</DataItem>\n",
               nodes)
        << "    </Attribute>\n   </Grid>\n";
  }
  out << "  </Grid>\n </Domain>\n</Xdmf>\n";
  if (!out) throw std::runtime_error("cannot write " + (run_dir / "mess.xdmf").string());
}

}  // namespace

void write_mess_results(const fs::path& run_dir, io::Hdf5File& results,
                        const ProtocolRunner& runner, const std::vector<StepRecord>& records) {
  const mc::MessSpec& spec = runner.spec();
  const char* unit = load_unit(spec);
  write_lattice(results, runner);
  const std::size_t np = runner.system().particle_count();
  write_step_records(results, "/steps", records, np, unit);
  const StepExtras x = step_extras(runner, records);
  const Eigen::Vector3d d = field_direction(spec);
  results.write_vector("/steps/field_direction", {d.x(), d.y(), d.z()}, "1");
  results.write_vector("/steps/field_projection", x.field_projection, "T");
  results.write_vector("/steps/magnetization_projection", x.magnetization_projection, "1");
  results.write_vector("/steps/energy_density", x.energy_density, "J/m^3");
  results.write_vector("/steps/separation", x.separation, "m");
  results.write_int_vector("/steps/cluster_count", x.cluster_count);
  results.write_int_vector("/steps/largest_cluster", x.largest_cluster);
  results.write_int_array("/steps/cluster_id", {records.size(), np}, x.cluster_id);
  write_summary(run_dir, records, x, unit);
  if (spec.strain || spec.stress) write_analysis(run_dir, results, runner, records, x);
  if (spec.output.node_positions) write_xdmf(run_dir, runner, records);
}

}  // namespace mresim::mess_protocol
