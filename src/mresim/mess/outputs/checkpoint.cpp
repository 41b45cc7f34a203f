#include "mresim/mess/outputs/checkpoint.hpp"

#include <fmt/format.h>

#include <bit>
#include <cstdint>
#include <memory>
#include <set>
#include <stdexcept>
#include <utility>
#include <vector>

#include "mresim/io/hdf5_file.hpp"
#include "mresim/io/hdf5_reader.hpp"
#include "mresim/mess/outputs/step_records_io.hpp"
#include "mresim/mess/protocols/step_plan.hpp"

namespace mresim::mess_protocol {

namespace fs = std::filesystem;

namespace {

// 2: the records have box_strain (a version-1 checkpoint cannot be resumed).
// 3: node arrays may be in array files (/array_files), the anchor's key is a root attribute.
constexpr std::int64_t kFormatVersion = 3;
constexpr std::int64_t kOldestReadable = 2;

// ProtocolState::earlier_field_result, where the state holds one.
constexpr const char* kEarlierFieldResult = "/earlier_field_result";
// ProtocolState::secant_miss and earlier_secant_miss, where the state holds them.
constexpr const char* kSecantMiss = "/secant_miss";
constexpr const char* kEarlierSecantMiss = "/earlier_secant_miss";
// ProtocolState::preconditioner_anchor, where the state holds one: its positions (single
// precision values, stored exactly as doubles); its key is the root attribute kAnchorKey
// (version 2: an attribute "key" of this dataset).
constexpr const char* kPreconditionerAnchor = "/preconditioner_anchor";
constexpr const char* kAnchorKey = "preconditioner_anchor_key";
// The index's list of array files: the arrays' paths and, in the same order, their files.
constexpr const char* kArrayPaths = "/array_files/paths";
constexpr const char* kArrayFileNames = "/array_files/files";
// The one dataset of an array file.
constexpr const char* kArrayDataset = "/array";

// By an array's path in the index, the name of its file in kArrayDirectory.
using ArrayNames = std::map<std::string, std::string>;

// visit(path, array) for each kept node array of the state (KeptPositions), holding one or not.
template <class State, class Visit>
void for_each_kept_array(State& state, Visit&& visit) {
  for (std::size_t i = 0; i < state.slots.size(); ++i) {
    visit(fmt::format("/slots/{}/positions", i), state.slots[i].positions);
  }
  for (std::size_t i = 0; i < state.references.size(); ++i) {
    visit(fmt::format("/references/{}", i), state.references[i]);
  }
  visit(std::string(kEarlierFieldResult), state.earlier_field_result);
  for (std::size_t i = 0; i < state.earlier_load_results.size(); ++i) {
    visit(fmt::format("/earlier_load_results/{}", i), state.earlier_load_results[i]);
  }
  visit(std::string(kSecantMiss), state.secant_miss);
  visit(std::string(kEarlierSecantMiss), state.earlier_secant_miss);
}

void write_optional(io::Hdf5File& file, const std::string& path, const Eigen::Matrix3Xd& m,
                    std::string_view unit) {
  if (m.cols() > 0) write_columns(file, path, m, unit);
}

Eigen::Matrix3Xd read_sized(const io::Hdf5Reader& file, const std::string& path,
                            Eigen::Index expected_columns, const std::string& where) {
  Eigen::Matrix3Xd m = read_columns(file, path);
  if (m.cols() != expected_columns) {
    throw std::runtime_error(
        fmt::format("checkpoint: {} has {} rows, expected {}", where, m.cols(), expected_columns));
  }
  return m;
}

// Writes `file` through "<file>.tmp" and a rename.
template <class Fill>
void write_replacing(const fs::path& file, Fill&& fill) {
  const fs::path temporary = fs::path(file.string() + ".tmp");
  {
    io::Hdf5File out(temporary);
    fill(out);
    out.close();
  }
  fs::rename(temporary, file);
}

// The node arrays of an index: inside it, or in the array files it names.
class ArraySource {
 public:
  ArraySource(const io::Hdf5Reader& index, const fs::path& index_file)
      : index_(index), directory_(index_file.parent_path() / kArrayDirectory) {
    if (!index.exists(kArrayPaths)) return;
    const std::vector<std::string> paths = index.strings(kArrayPaths);
    const std::vector<std::string> files = index.strings(kArrayFileNames);
    if (paths.size() != files.size()) {
      throw std::runtime_error("checkpoint " + index_file.string() +
                               ": its lists of array files differ in length");
    }
    for (std::size_t k = 0; k < paths.size(); ++k) names_[paths[k]] = files[k];
  }

  const ArrayNames& names() const { return names_; }

  // The array at `path` (3 x 0 where the checkpoint has none).
  Eigen::Matrix3Xd read(const std::string& path, Eigen::Index expected_columns) const {
    if (index_.exists(path)) return read_sized(index_, path, expected_columns, path);
    const auto named = names_.find(path);
    if (named == names_.end()) return {};
    const fs::path file = directory_ / named->second;
    const io::Hdf5Reader in(file);
    return read_sized(in, kArrayDataset, expected_columns, file.string());
  }

 private:
  const io::Hdf5Reader& index_;
  fs::path directory_;
  ArrayNames names_;
};

// The index: everything but the node arrays named in `arrays` (null: every array inside it).
void write_index(const fs::path& file, const ProtocolState& state, const ProtocolRunner& runner,
                 std::string_view input_toml, std::string_view input_name,
                 const ArrayNames* arrays) {
  write_replacing(file, [&](io::Hdf5File& out) {
    out.write_int_attribute("/", "format_version", kFormatVersion);
    out.write_string_attribute("/", "input_toml", input_toml);
    out.write_string_attribute("/", "input_file", input_name);
    out.write_int_attribute("/", "next_step", static_cast<std::int64_t>(state.next_step));
    out.write_int_attribute("/", "slots", static_cast<std::int64_t>(state.slots.size()));
    out.write_int_attribute("/", "references", static_cast<std::int64_t>(state.references.size()));
    for (std::size_t i = 0; i < state.slots.size(); ++i) {
      write_optional(out, fmt::format("/slots/{}/magnetization", i), state.slots[i].magnetization,
                     "A/m");
    }
    if (arrays == nullptr) {
      for_each_kept_array(state, [&out](const std::string& path, const KeptPositions& x) {
        if (x.cols() > 0) write_columns(out, path, x.load(), "m");
      });
      if (state.preconditioner_anchor != nullptr) {
        write_columns(out, kPreconditionerAnchor,
                      state.preconditioner_anchor->positions.cast<double>(), "m");
      }
    } else if (!arrays->empty()) {
      std::vector<std::string> paths;
      std::vector<std::string> files;
      for (const auto& [path, name] : *arrays) {
        paths.push_back(path);
        files.push_back(name);
      }
      out.write_string_vector(kArrayPaths, paths);
      out.write_string_vector(kArrayFileNames, files);
    }
    if (state.preconditioner_anchor != nullptr) {
      out.write_int_attribute("/", kAnchorKey,
                              std::bit_cast<std::int64_t>(state.preconditioner_anchor->key));
    }
    if (!state.records.empty()) {
      write_step_records(out, "/records", state.records, runner.system().particle_count(),
                         load_unit(runner.spec()), *runner.system().energy_labels());
    }
  });
}

// "slots-3-positions" for "/slots/3/positions".
std::string file_tag(const std::string& path) {
  std::string tag = path.substr(path.find_first_not_of('/'));
  for (char& c : tag) {
    if (c == '/') c = '-';
  }
  return tag;
}

}  // namespace

void write_checkpoint(const fs::path& file, const ProtocolState& state,
                      const ProtocolRunner& runner, std::string_view input_toml,
                      std::string_view input_name) {
  write_index(file, state, runner, input_toml, input_name, nullptr);
}

ProtocolState read_checkpoint(const fs::path& file, const ProtocolRunner& runner,
                              std::string_view input_toml) {
  const io::Hdf5Reader in(file);
  const std::int64_t version = in.int_attribute("/", "format_version");
  if (version < kOldestReadable || version > kFormatVersion) {
    throw std::runtime_error("checkpoint " + file.string() + ": unknown format version");
  }
  if (in.string_attribute("/", "input_toml") != input_toml) {
    throw std::runtime_error("checkpoint " + file.string() +
                             " was written for a different run file");
  }
  ProtocolState state = runner.initial_state();
  const auto next = static_cast<std::size_t>(in.int_attribute("/", "next_step"));
  if (next > runner.steps().size() ||
      static_cast<std::size_t>(in.int_attribute("/", "slots")) != state.slots.size() ||
      static_cast<std::size_t>(in.int_attribute("/", "references")) != state.references.size()) {
    throw std::runtime_error("checkpoint " + file.string() + " does not match the run's steps");
  }
  const Eigen::Index nodes = runner.system().node_count();
  const auto particles = static_cast<Eigen::Index>(runner.system().particle_count());
  const ArraySource arrays(in, file);
  for_each_kept_array(state, [&](const std::string& path, KeptPositions& x) {
    // Absent: no such array (a field not reached yet; a run without the field secant).
    x = arrays.read(path, nodes);
    runner.park_kept_positions(state);  // one field's array in memory at a time, at most
  });
  for (std::size_t i = 0; i < state.slots.size(); ++i) {
    const std::string path = fmt::format("/slots/{}/magnetization", i);
    if (in.exists(path)) state.slots[i].magnetization = read_sized(in, path, particles, path);
  }
  // Absent in checkpoints of runs that build the preconditioner at every step (and in those
  // written before it was kept).
  const Eigen::Matrix3Xd anchor = arrays.read(kPreconditionerAnchor, nodes);
  if (anchor.cols() > 0) {
    const std::int64_t key = version == 2 ? in.int_attribute(kPreconditionerAnchor, "key")
                                          : in.int_attribute("/", kAnchorKey);
    state.preconditioner_anchor = std::make_shared<const mess::PreconditionerAnchor>(
        mess::PreconditionerAnchor{anchor.cast<float>(), std::bit_cast<std::uint64_t>(key)});
  }
  if (next > 0) {
    state.records =
        read_step_records(in, "/records", runner.steps(), runner.system().particle_count(),
                          runner.system().energy_labels());
  }
  if (state.records.size() != next) {
    throw std::runtime_error("checkpoint " + file.string() + ": records do not match next_step");
  }
  state.next_step = next;
  return state;
}

CheckpointWriter::CheckpointWriter(fs::path directory) : directory_(std::move(directory)) {}

bool CheckpointWriter::exists() const { return fs::exists(directory_ / kCheckpointFile); }

namespace {

// Removes the files of `directory` that `named` does not name (left by a write that did not
// finish, or named by an index replaced since). A file that cannot be removed stays (the next
// call tries again): the checkpoint is complete without it.
void remove_unnamed(const fs::path& directory, const std::set<std::string>& named) {
  std::error_code ec;
  if (!fs::is_directory(directory, ec)) return;
  std::vector<fs::path> stale;
  for (const auto& entry : fs::directory_iterator(directory, ec)) {
    if (entry.is_regular_file(ec) && !named.contains(entry.path().filename().string())) {
      stale.push_back(entry.path());
    }
  }
  for (const fs::path& file : stale) fs::remove(file, ec);
}

}  // namespace

ProtocolState CheckpointWriter::read(const ProtocolRunner& runner, std::string_view input_toml) {
  const fs::path index = directory_ / kCheckpointFile;
  ProtocolState state = read_checkpoint(index, runner, input_toml);
  ArrayNames names;
  {
    const io::Hdf5Reader in(index);
    names = ArraySource(in, index).names();
  }
  written_.clear();
  for_each_kept_array(state, [&](const std::string& path, const KeptPositions& x) {
    const auto named = names.find(path);
    if (named != names.end() && x.cols() > 0) written_[path] = {x.version(), named->second};
  });
  const auto anchor = names.find(kPreconditionerAnchor);
  if (anchor != names.end() && state.preconditioner_anchor != nullptr) {
    written_[kPreconditionerAnchor] = {0, anchor->second};
    anchor_written_ = state.preconditioner_anchor;
  }
  std::set<std::string> named;
  for (const auto& [path, file] : written_) named.insert(file.file);
  remove_unnamed(directory_ / kArrayDirectory, named);
  return state;
}

void CheckpointWriter::write(const ProtocolState& state, const ProtocolRunner& runner,
                             std::string_view input_toml, std::string_view input_name) {
  const fs::path arrays = directory_ / kArrayDirectory;
  fs::create_directories(arrays);
  std::set<std::string> in_use;  // the files the current index names: never written over
  for (const auto& [path, file] : written_) in_use.insert(file.file);
  std::map<std::string, ArrayFile> now;
  const auto keep = [&](const std::string& path, bool unchanged, std::uint64_t version,
                        const auto& load) {
    const auto old = written_.find(path);
    if (unchanged && old != written_.end()) {
      now[path] = old->second;
      return;
    }
    std::string name = fmt::format("{}-{}.h5", file_tag(path), state.next_step);
    for (int k = 2; in_use.contains(name); ++k) {
      name = fmt::format("{}-{}-{}.h5", file_tag(path), state.next_step, k);
    }
    write_replacing(arrays / name,
                    [&](io::Hdf5File& out) { write_columns(out, kArrayDataset, load(), "m"); });
    in_use.insert(name);
    now[path] = {version, name};
  };
  for_each_kept_array(state, [&](const std::string& path, const KeptPositions& x) {
    if (x.cols() == 0) return;
    const auto old = written_.find(path);
    keep(path, old != written_.end() && old->second.version == x.version(), x.version(),
         [&x] { return x.load(); });
  });
  const std::shared_ptr<const mess::PreconditionerAnchor>& anchor = state.preconditioner_anchor;
  if (anchor != nullptr) {
    keep(kPreconditionerAnchor, anchor_written_.lock() == anchor, 0,
         [&anchor] { return Eigen::Matrix3Xd(anchor->positions.cast<double>()); });
  }
  ArrayNames names;
  for (const auto& [path, file] : now) names[path] = file.file;
  write_index(directory_ / kCheckpointFile, state, runner, input_toml, input_name, &names);
  written_ = std::move(now);
  anchor_written_ = anchor;
  std::set<std::string> named;
  for (const auto& [path, file] : written_) named.insert(file.file);
  remove_unnamed(arrays, named);
}

void CheckpointWriter::remove() {
  std::error_code ec;
  fs::remove(directory_ / kCheckpointFile, ec);
  remove_unnamed(directory_ / kArrayDirectory, {});
  fs::remove(directory_ / kArrayDirectory, ec);  // empty now; absent without array files
  written_.clear();
  anchor_written_.reset();
}

std::map<std::string, std::string> CheckpointWriter::array_files() const {
  std::map<std::string, std::string> files;
  for (const auto& [path, file] : written_) files[path] = file.file;
  return files;
}

}  // namespace mresim::mess_protocol
