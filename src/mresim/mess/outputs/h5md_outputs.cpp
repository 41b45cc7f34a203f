#include "mresim/mess/outputs/h5md_outputs.hpp"

#include <pwd.h>
#include <unistd.h>

#include <mresim/core/version.hpp>
#include <string>
#include <utility>

#include "mresim/mess/outputs/mess_outputs.hpp"

namespace mresim::mess_protocol {

namespace {

constexpr const char* kParticles = "/particles/magnetic_particles";
// The one step and time of every time-dependent element (the others link to them).
constexpr const char* kH5mdStep = "/particles/magnetic_particles/position/step";
constexpr const char* kH5mdTime = "/particles/magnetic_particles/position/time";
constexpr double kNanometresPerMetre = 1e9;

// The login name of the user running mresim (H5MD's author); "unknown" when there is none.
std::string author_name() {
  std::string buffer(4096, '\0');
  passwd entry{};
  passwd* found = nullptr;
  if (getpwuid_r(getuid(), &entry, buffer.data(), buffer.size(), &found) == 0 && found != nullptr &&
      found->pw_name != nullptr && *found->pw_name != '\0') {
    return found->pw_name;
  }
  return "unknown";
}

void write_h5md_group(io::Hdf5File& results) {
  results.write_int_vector_attribute("/h5md", "version", {1, 1});
  results.write_string_attribute("/h5md/author", "name", author_name());
  results.write_string_attribute("/h5md/creator", "name", "mresim");
  results.write_string_attribute("/h5md/creator", "version", kVersion);
}

// A time-dependent H5MD element at `group`: its value is the existing dataset `value` (hard
// link), its step and time the shared ones.
void link_element(io::Hdf5File& results, const std::string& group, const std::string& value) {
  results.hard_link(kH5mdStep, group + "/step");
  results.hard_link(kH5mdTime, group + "/time");
  results.hard_link(value, group + "/value");
}

// The non-periodic box of a particle group: the lattice is a finite block with free or held
// faces, so there are no periodic images and no edges (the initial box is
// /parameters/box_lengths, its strain the observable box_strain).
void write_box(io::Hdf5File& results, const std::string& group) {
  results.write_int_attribute(group + "/box", "dimension", 3);
  results.write_string_vector_attribute(group + "/box", "boundary", {"none", "none", "none"});
}

void write_magnetic_particles(io::Hdf5File& results, const std::vector<StepRecord>& records,
                              std::size_t particle_count) {
  const std::string g = kParticles;
  write_box(results, g);
  std::vector<std::int64_t> step;
  std::vector<double> time;
  for (const StepRecord& r : records) {
    step.push_back(static_cast<std::int64_t>(r.step.index));
    time.push_back(static_cast<double>(r.step.index));
  }
  results.write_int_vector(kH5mdStep, step);
  // No unit: the time of a quasi-static step is its index (docs/outputs-3d.md, "H5MD").
  results.write_vector(kH5mdTime, time, {});
  // Nanometres: MDAnalysis' H5MD reader refuses lengths in m (it knows Angstrom, nm, pm, fm).
  std::vector<double> nm;
  nm.reserve(records.size() * particle_count * 3);
  for (const StepRecord& r : records) {
    for (Eigen::Index p = 0; p < r.centres.cols(); ++p) {
      for (Eigen::Index a = 0; a < 3; ++a) nm.push_back(r.centres(a, p) * kNanometresPerMetre);
    }
  }
  results.write_array(g + "/position/value", {records.size(), particle_count, 3}, nm, "nm");
  link_element(results, g + "/magnetization", "/steps/magnetization");
  link_element(results, g + "/cluster_id", "/steps/cluster_id");
}

// The lattice nodes, with node positions: a virtual dataset over the per-step files (in m, as
// they are written; MDAnalysis reads only the first particle group, magnetic_particles).
void write_nodes(io::Hdf5File& results, const std::vector<StepRecord>& records,
                 std::size_t node_count) {
  const std::string g = "/particles/nodes";
  write_box(results, g);
  std::vector<std::pair<std::string, std::string>> sources;
  sources.reserve(records.size());
  for (const StepRecord& r : records) {
    sources.emplace_back(step_positions_file("", r.step.index).string(), "/positions");
  }
  results.write_virtual_stack(g + "/position/value", {node_count, 3}, sources, "m");
  results.hard_link(kH5mdStep, g + "/position/step");
  results.hard_link(kH5mdTime, g + "/position/time");
  results.hard_link("/lattice/particle_id", g + "/particle_id");
}

// Every per-step quantity of /steps that exists for this run, under a flat name (MDAnalysis
// reads observables/<name>/value only one level deep).
void write_observables(io::Hdf5File& results, const mess::TermLabels& terms) {
  std::vector<std::pair<std::string, std::string>> links = {
      {"field", "/steps/field"},
      {"field_projection", "/steps/field_projection"},
      {"load_value", "/steps/load_value"},
      {"measured_strain", "/steps/measured_strain"},
      {"energy_total", "/steps/energies/total"},
      {"energy_density", "/steps/energy_density"},
      {"system_volume", "/steps/system_volume"},
      {"magnetization_projection", "/steps/magnetization_projection"},
      {"separation", "/steps/separation"},
      {"pair_angle", "/steps/pair_angle"},
      {"cluster_count", "/steps/cluster_count"},
      {"largest_cluster", "/steps/largest_cluster"},
      {"box_strain", "/steps/box_strain"},
      {"magnetostriction", "/steps/magnetostriction"},
      {"valid", "/steps/valid"},
      {"converged", "/steps/solver/converged"}};
  for (const mess::TermLabel& t : terms) {
    links.emplace_back("energy_" + t.name, "/steps/energies/" + t.name);
  }
  for (const auto& [name, path] : links) {
    if (results.exists(path)) link_element(results, "/observables/" + name, path);
  }
}

void write_parameters(io::Hdf5File& results, const ProtocolRunner& runner) {
  const mess_config::MessSpec& spec = runner.spec();
  const lattice::Lattice& lat = runner.system().lattice();
  results.write_number_attribute("/parameters", "element_length", lat.element_length);
  results.write_number_attribute("/parameters", "particle_radius", lat.particle_radius);
  results.write_number_attribute("/parameters", "saturation_magnetization", spec.particles.Ms);
  results.write_number_attribute("/parameters", "volume_fraction", lat.volume_fraction());
  results.write_string_attribute("/parameters", "units",
                                 "element_length, particle_radius: m; "
                                 "saturation_magnetization: A/m; volume_fraction: 1");
  results.hard_link("/lattice/box_lengths", "/parameters/box_lengths");
  results.hard_link("/lattice/initial_centres", "/parameters/initial_centres");
  results.hard_link("/steps/field_direction", "/parameters/field_direction");
}

}  // namespace

void write_h5md(io::Hdf5File& results, const ProtocolRunner& runner,
                const std::vector<StepRecord>& records) {
  write_h5md_group(results);
  write_magnetic_particles(results, records, runner.system().particle_count());
  if (runner.spec().output.node_positions) {
    write_nodes(results, records, runner.system().lattice().node_count());
  }
  write_observables(results, *runner.system().energy_labels());
  write_parameters(results, runner);
}

}  // namespace mresim::mess_protocol
