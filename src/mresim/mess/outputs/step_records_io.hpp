#pragma once

// The per-step records of a 3D run as HDF5 datasets under one group, written and read back.
// Used twice: by checkpoints (so a resumed run has the records of the steps it did not redo)
// and by results.h5's /steps (docs/outputs-3d.md lists every dataset and unit).

#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "mresim/io/hdf5_file.hpp"
#include "mresim/io/hdf5_reader.hpp"
#include "mresim/mess/protocols/protocol_runner.hpp"

namespace mresim::mess_protocol {

// Writes /<group>/index, field, field_index, load_index, load_value, energies/<term> for every
// term of `terms` (the system's list, MessSystem::energy_labels(); each dataset with string
// attributes `equation` and `title`) and energies/total, system_volume, measured_strain,
// box_strain, centres, magnetization and solver/<diagnostic>. A record without a term's value
// gets NaN.
void write_step_records(io::Hdf5File& file, const std::string& group,
                        const std::vector<StepRecord>& records, std::size_t particle_count,
                        const char* load_unit, const mess::TermLabels& terms);

// Reads them back; `steps` (the run's plan) restores each record's StepSpec by index, `terms`
// (the system's labels) its energies.
std::vector<StepRecord> read_step_records(const io::Hdf5Reader& file, const std::string& group,
                                          const std::vector<StepSpec>& steps,
                                          std::size_t particle_count,
                                          const std::shared_ptr<const mess::TermLabels>& terms);

// The value of term `name` in `energies`, NaN if it has none.
double energy_or_nan(const mess::MessEnergies& energies, std::string_view name);

// 3 x N matrices <-> N x 3 datasets.
void write_columns(io::Hdf5File& file, const std::string& path, const Eigen::Matrix3Xd& m,
                   std::string_view unit);
Eigen::Matrix3Xd read_columns(const io::Hdf5Reader& file, const std::string& path);

}  // namespace mresim::mess_protocol
