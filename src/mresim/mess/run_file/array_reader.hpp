#pragma once

// Readers for the array shapes of the 3D run file that config::TableReader has no getter for:
// fixed-size vectors ([x, y, z]), lists of vectors ([[x, y, z], ...]) and integer triples
// ([1, 1, 2]). Same conventions as TableReader: the key is recorded as known, every error is
// one line "table.key[i][j] = value: what is allowed (unit)" and a config::ConfigError.
//
// TableReader keeps its toml nodes private, so these read the document again from
// TableReader::source_text() and walk to the table by its dotted path (plain table names only,
// which is all the 3D schema uses). Candidates for TableReader itself once config/ is open.

#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "mresim/config/table_reader.hpp"

namespace mresim::mess_config {

// [x, y, z]: exactly three finite numbers, each in `range`.
std::optional<Eigen::Vector3d> optional_vector3(const config::TableReader& table,
                                                std::string_view key, const config::Range& range,
                                                std::string_view unit);

// [[x, y, z], ...] with at least `min_size` entries, every component in `range`.
std::optional<std::vector<Eigen::Vector3d>> optional_vector3_list(const config::TableReader& table,
                                                                  std::string_view key,
                                                                  const config::Range& range,
                                                                  std::string_view unit,
                                                                  std::size_t min_size = 1);

// [a, b, c]: exactly three TOML integers (2.0 is rejected), each in `range`.
std::optional<std::array<long, 3>> optional_integer3(const config::TableReader& table,
                                                     std::string_view key,
                                                     const config::Range& range);

// Whether the value of `key` is a TOML array (false if absent). Does not mark the key as known.
bool is_array(const config::TableReader& table, std::string_view key);

// "[6e-06, 6e-06, 1.5e-05]", numbers as TableReader writes them (for callers' messages).
std::string vector_text(const Eigen::Vector3d& v);

}  // namespace mresim::mess_config
