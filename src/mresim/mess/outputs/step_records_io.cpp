#include "mresim/mess/outputs/step_records_io.hpp"

#include <limits>
#include <stdexcept>

namespace mresim::mess_protocol {

double energy_or_nan(const mess::MessEnergies& energies, std::string_view name) {
  return energies.has(name) ? energies[name] : std::numeric_limits<double>::quiet_NaN();
}

void write_columns(io::Hdf5File& file, const std::string& path, const Eigen::Matrix3Xd& m,
                   std::string_view unit) {
  // Column-major 3 x N is row-major N x 3.
  file.write_matrix(path, static_cast<std::size_t>(m.cols()), 3,
                    std::vector<double>(m.data(), m.data() + m.size()), unit);
}

Eigen::Matrix3Xd read_columns(const io::Hdf5Reader& file, const std::string& path) {
  const std::vector<std::size_t> shape = file.shape(path);
  if (shape.size() != 2 || shape[1] != 3) {
    throw std::runtime_error("expected an N x 3 dataset at " + path);
  }
  const std::vector<double> values = file.doubles(path);
  return Eigen::Map<const Eigen::Matrix3Xd>(values.data(), 3, static_cast<Eigen::Index>(shape[0]));
}

namespace {

template <typename Get>
std::vector<double> column(const std::vector<StepRecord>& records, Get get) {
  std::vector<double> out;
  out.reserve(records.size());
  for (const StepRecord& r : records) out.push_back(static_cast<double>(get(r)));
  return out;
}

template <typename Get>
std::vector<std::int64_t> int_column(const std::vector<StepRecord>& records, Get get) {
  std::vector<std::int64_t> out;
  out.reserve(records.size());
  for (const StepRecord& r : records) out.push_back(static_cast<std::int64_t>(get(r)));
  return out;
}

std::vector<std::string> string_column(const std::vector<StepRecord>& records,
                                       const std::string StepRecord::*member) {
  std::vector<std::string> out;
  out.reserve(records.size());
  for (const StepRecord& r : records) out.push_back(r.*member);
  return out;
}

// A column that older files lack: `fallback` for each of the n steps where it is absent.
std::vector<std::string> strings_or(const io::Hdf5Reader& file, const std::string& path,
                                    std::size_t n, const std::string& fallback = "unrecorded") {
  return file.exists(path) ? file.strings(path) : std::vector<std::string>(n, fallback);
}

std::vector<std::int64_t> ints_or(const io::Hdf5Reader& file, const std::string& path,
                                  std::size_t n, std::int64_t fallback) {
  std::vector<std::int64_t> v(n, fallback);
  if (!file.exists(path)) return v;
  v = file.ints(path);
  if (v.size() != n) throw std::runtime_error("inconsistent length of " + path);
  return v;
}

// steps x particles x 3 from each record's 3 x N_p matrix.
std::vector<double> stacked(const std::vector<StepRecord>& records,
                            const Eigen::Matrix3Xd StepRecord::*member) {
  std::vector<double> out;
  for (const StepRecord& r : records) {
    const Eigen::Matrix3Xd& m = r.*member;
    out.insert(out.end(), m.data(), m.data() + m.size());
  }
  return out;
}

}  // namespace

void write_step_records(io::Hdf5File& file, const std::string& group,
                        const std::vector<StepRecord>& records, std::size_t particle_count,
                        const char* load_unit, const mess::TermLabels& terms) {
  const std::string g = group + "/";
  file.create_group(group);
  file.write_int_vector(g + "index", int_column(records, [](auto& r) { return r.step.index; }));
  std::vector<double> field;
  for (const StepRecord& r : records)
    field.insert(field.end(), {r.step.field.x(), r.step.field.y(), r.step.field.z()});
  file.write_matrix(g + "field", records.size(), 3, field, "T");
  file.write_int_vector(g + "field_index",
                        int_column(records, [](auto& r) { return r.step.field_index; }));
  file.write_int_vector(g + "load_index",
                        int_column(records, [](auto& r) { return r.step.load_index; }));
  file.write_vector(g + "load_value", column(records, [](auto& r) { return r.step.load_value; }),
                    load_unit);
  for (const mess::TermLabel& t : terms) {
    const std::string path = g + "energies/" + t.name;
    file.write_vector(
        path, column(records, [&](auto& r) { return energy_or_nan(r.energies, t.name); }), "J");
    file.write_string_attribute(path, "equation", t.equation);
    file.write_string_attribute(path, "title", t.title);
  }
  // The list order (HDF5 lists a group's members by name).
  std::string order;
  for (const mess::TermLabel& t : terms) order += (order.empty() ? "" : ",") + t.name;
  if (!terms.empty()) file.write_string_attribute(g + "energies", "terms", order);
  file.write_vector(g + "energies/total",
                    column(records, [](auto& r) { return r.energies.total(); }), "J");
  file.write_vector(g + "system_volume", column(records, [](auto& r) { return r.system_volume; }),
                    "m^3");
  file.write_vector(g + "measured_strain",
                    column(records, [](auto& r) { return r.measured_strain; }), load_unit);
  std::vector<double> box_strain;
  for (const StepRecord& r : records) {
    box_strain.insert(box_strain.end(), {r.box_strain.x(), r.box_strain.y(), r.box_strain.z()});
  }
  file.write_matrix(g + "box_strain", records.size(), 3, box_strain, "1");
  const std::vector<std::size_t> dims = {records.size(), particle_count, 3};
  file.write_array(g + "centres", dims, stacked(records, &StepRecord::centres), "m");
  file.write_array(g + "magnetization", dims, stacked(records, &StepRecord::magnetization), "A/m");

  const std::string s = g + "solver/";
  file.write_int_vector(s + "converged", int_column(records, [](auto& r) { return r.converged; }));
  std::vector<std::string> status;
  std::vector<std::string> method;
  for (const StepRecord& r : records) {
    status.push_back(r.status);
    method.push_back(r.magnetization_method);
  }
  file.write_string_vector(s + "status", status);
  file.write_int_vector(s + "iterations",
                        int_column(records, [](auto& r) { return r.iterations; }));
  file.write_int_vector(s + "evaluations",
                        int_column(records, [](auto& r) { return r.evaluations; }));
  file.write_int_vector(s + "krylov_iterations",
                        int_column(records, [](auto& r) { return r.krylov_iterations; }));
  file.write_string_vector(s + "finished_by", string_column(records, &StepRecord::finished_by));
  file.write_string_vector(s + "start", string_column(records, &StepRecord::start));
  file.write_string_vector(s + "preconditioner",
                           string_column(records, &StepRecord::preconditioner));
  file.write_int_vector(s + "correction_passes",
                        int_column(records, [](auto& r) { return r.correction_passes; }));
  file.write_vector(s + "max_force", column(records, [](auto& r) { return r.max_force; }), "N");
  file.write_int_vector(s + "magnetization_solves",
                        int_column(records, [](auto& r) { return r.magnetization_solves; }));
  file.write_int_vector(s + "unconverged_magnetization_solves", int_column(records, [](auto& r) {
                          return r.unconverged_magnetization_solves;
                        }));
  file.write_string_vector(s + "magnetization_method", method);
  file.write_int_vector(s + "magnetization_iterations",
                        int_column(records, [](auto& r) { return r.magnetization_iterations; }));
  file.write_vector(s + "magnetization_residual",
                    column(records, [](auto& r) { return r.magnetization_residual; }), "1");
  file.write_vector(s + "wall_time", column(records, [](auto& r) { return r.wall_time; }), "s");
  file.write_int_vector(s + "peak_resident_memory",
                        int_column(records, [](auto& r) { return r.peak_resident_memory; }), "B");
}

std::vector<StepRecord> read_step_records(const io::Hdf5Reader& file, const std::string& group,
                                          const std::vector<StepSpec>& steps,
                                          std::size_t particle_count,
                                          const std::shared_ptr<const mess::TermLabels>& terms) {
  const std::string g = group + "/";
  const std::vector<std::int64_t> index = file.ints(g + "index");
  const std::size_t n = index.size();
  std::vector<StepRecord> records(n);
  const auto doubles = [&](const std::string& path) {
    std::vector<double> v = file.doubles(path);
    if (v.size() != n) throw std::runtime_error("inconsistent length of " + path);
    return v;
  };
  const auto ints = [&](const std::string& path) {
    std::vector<std::int64_t> v = file.ints(path);
    if (v.size() != n) throw std::runtime_error("inconsistent length of " + path);
    return v;
  };
  for (std::size_t i = 0; i < n; ++i) {
    if (index[i] < 0 || static_cast<std::size_t>(index[i]) >= steps.size()) {
      throw std::runtime_error("step index out of range in " + g + "index");
    }
    records[i].step = steps[static_cast<std::size_t>(index[i])];
  }
  for (StepRecord& r : records) r.energies = mess::MessEnergies(terms);
  for (std::size_t k = 0; k < (terms ? terms->size() : 0); ++k) {
    const std::vector<double> v = doubles(g + "energies/" + (*terms)[k].name);
    for (std::size_t i = 0; i < n; ++i) records[i].energies.value(k) = v[i];
  }
  const std::vector<double> volume = doubles(g + "system_volume");
  const std::vector<double> strain = doubles(g + "measured_strain");
  const std::vector<double> box_strain = file.doubles(g + "box_strain");
  if (box_strain.size() != 3 * n)
    throw std::runtime_error("inconsistent length of " + g + "box_strain");
  const std::vector<double> centres = file.doubles(g + "centres");
  const std::vector<double> magnetization = file.doubles(g + "magnetization");
  const std::size_t per_step = 3 * particle_count;
  if (centres.size() != n * per_step || magnetization.size() != n * per_step) {
    throw std::runtime_error("inconsistent particle data in " + group);
  }
  const std::string s = g + "solver/";
  const std::vector<std::int64_t> converged = ints(s + "converged");
  const std::vector<std::string> status = file.strings(s + "status");
  const std::vector<std::int64_t> iterations = ints(s + "iterations");
  const std::vector<std::int64_t> evaluations = ints(s + "evaluations");
  // Absent in files written before these were recorded: 0 or "unrecorded" (for the
  // preconditioner, such runs built the multilevel one at every step's start).
  const std::vector<std::int64_t> krylov = ints_or(file, s + "krylov_iterations", n, 0);
  const std::vector<std::string> finished_by = strings_or(file, s + "finished_by", n);
  const std::vector<std::string> start = strings_or(file, s + "start", n);
  const std::vector<std::string> preconditioner = strings_or(file, s + "preconditioner", n);
  const std::vector<std::int64_t> passes = ints_or(file, s + "correction_passes", n, 0);
  const std::vector<double> max_force = doubles(s + "max_force");
  const std::vector<std::int64_t> solves = ints(s + "magnetization_solves");
  const std::vector<std::int64_t> unconverged = ints(s + "unconverged_magnetization_solves");
  const std::vector<std::string> method = file.strings(s + "magnetization_method");
  const std::vector<std::int64_t> m_iterations = ints(s + "magnetization_iterations");
  const std::vector<double> m_residual = doubles(s + "magnetization_residual");
  const std::vector<double> wall = doubles(s + "wall_time");
  // Absent in files written before the peak memory was recorded per step: 0.
  const std::vector<std::int64_t> peak_memory = ints_or(file, s + "peak_resident_memory", n, 0);
  if (status.size() != n || method.size() != n || finished_by.size() != n || start.size() != n ||
      preconditioner.size() != n) {
    throw std::runtime_error("inconsistent solver data in " + group);
  }
  const auto np = static_cast<Eigen::Index>(particle_count);
  for (std::size_t i = 0; i < n; ++i) {
    StepRecord& r = records[i];
    r.system_volume = volume[i];
    r.measured_strain = strain[i];
    r.box_strain = Eigen::Vector3d(box_strain[3 * i], box_strain[3 * i + 1], box_strain[3 * i + 2]);
    r.centres = Eigen::Map<const Eigen::Matrix3Xd>(centres.data() + i * per_step, 3, np);
    r.magnetization =
        Eigen::Map<const Eigen::Matrix3Xd>(magnetization.data() + i * per_step, 3, np);
    r.converged = converged[i] != 0;
    r.status = status[i];
    r.iterations = iterations[i];
    r.evaluations = evaluations[i];
    r.krylov_iterations = krylov[i];
    r.finished_by = finished_by[i];
    r.start = start[i];
    r.preconditioner = preconditioner[i];
    r.correction_passes = passes[i];
    r.max_force = max_force[i];
    r.magnetization_solves = solves[i];
    r.unconverged_magnetization_solves = unconverged[i];
    r.magnetization_method = method[i];
    r.magnetization_iterations = m_iterations[i];
    r.magnetization_residual = m_residual[i];
    r.wall_time = wall[i];
    r.peak_resident_memory = peak_memory[i];
  }
  return records;
}

}  // namespace mresim::mess_protocol
