#pragma once

// The [sweep] table of a run file (docs/sweeps.md): one run file describing a study over any of
// its values. Two kinds of axes, both keyed by the dotted keys of `--set` (config/overrides.hpp):
//
//   [sweep]
//   product = { "particles.volume_fraction" = [0.03, 0.05], "field.theta" = [0, 90] }
//   zip = { "model.youngs_modulus" = [9e3, 18e3], "run.title" = ["soft", "stiff"] }
//
// `product` takes every combination of its lists; `zip` takes its lists element by element (all
// of one length), together forming one more axis. The points are the cartesian product of the
// zip axis (outermost) and the product lists in the order written, the last varying fastest.
// Each point is the run file without [sweep] plus one override per swept key, so it is
// validated exactly as `mresim run FILE --set KEY=VALUE ...` would be.

#include <toml++/toml.h>

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

namespace mresim::sweep {

struct SweepPoint {
  std::size_t index = 0;
  // One "KEY=VALUE" argument of `--set` per swept key, in the order of SweepSpec::keys.
  std::vector<std::string> overrides;
  // The values, one per swept key, as TOML text ("0.05", "\"seed\"", "[1, 1, 2]").
  std::vector<std::string> values;
};

struct SweepSpec {
  // The run file without its [sweep] table, as TOML text (what every point starts from).
  std::string base_text;
  // The swept keys: the zip keys, then the product keys, each in the order written.
  std::vector<std::string> keys;
  std::vector<SweepPoint> points;
};

// Whether the parsed run file has a [sweep] table.
[[nodiscard]] bool has_sweep(const toml::table& root);

// Expands the [sweep] table of `root` (which must have one). Throws ConfigError naming the key,
// the value and what is allowed for a malformed table: unknown keys in [sweep], a list that is
// not a non-empty array, zip lists of different lengths, a key swept twice, a key that is not a
// valid `--set` key. Whether the values suit the run type is checked per point by the caller
// (app::make_plan on each point).
[[nodiscard]] SweepSpec expand_sweep(const toml::table& root);

// `node` as one-line TOML text, floats in their shortest round-trip form kept recognisable as
// floats ("0.05", "1.0", "[1, 1, 2]", "\"seed\"", "{a = 1}").
[[nodiscard]] std::string toml_value_text(const toml::node& node);

}  // namespace mresim::sweep
