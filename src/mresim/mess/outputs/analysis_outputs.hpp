#pragma once

// /analysis of results.h5 and modulus.csv (docs/outputs-3d.md): per field, the modulus fit the
// protocol names (Section 4.2.8; analysis/modulus_fit.hpp), the fit of the branch after a kink
// (analysis/second_fit.hpp; Figs. 4.25-4.26) and the MR effect.

#include <filesystem>
#include <vector>

#include "mresim/io/hdf5_file.hpp"
#include "mresim/mess/outputs/mess_outputs.hpp"
#include "mresim/mess/protocols/protocol_runner.hpp"

namespace mresim::mess_protocol {

// energy_density: per record, J/m^3. Invalid first fits go to check.invalid_fits (warnings);
// a second fit that is not valid is no warning (most curves have no kink).
void write_analysis(const std::filesystem::path& run_dir, io::Hdf5File& results,
                    const ProtocolRunner& runner, const std::vector<StepRecord>& records,
                    const std::vector<double>& energy_density, MessResultCheck& check);

}  // namespace mresim::mess_protocol
