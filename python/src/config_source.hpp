#pragma once

#include <pybind11/pybind11.h>

#include <string>
#include <vector>

#include "mresim/config/table_reader.hpp"

namespace mresim::python {

// A run file given from Python, parsed as `mresim run`/`info` parse theirs:
//   dict              the tables as nested dicts/lists (source name "<dict>");
//   str               TOML text (source name "<string>");
//   os.PathLike       a run file on disk, named in messages as given (as on the command line).
// `overrides` are `--set KEY=VALUE` arguments, applied and validated as on the command line.
// Throws config::ConfigError with the command line's message for anything wrong.
config::TableReader read_config(const pybind11::handle& source,
                                const std::vector<std::string>& overrides);

// The TOML text of a dict of tables: nested dicts become tables, lists arrays (a list of
// dicts an array of tables), bool/int/float/str the TOML values; numpy scalars and arrays are
// taken through .tolist(). Anything else (None, objects) is a ConfigError naming the key.
std::string toml_text_of_dict(const pybind11::dict& tables);

}  // namespace mresim::python
