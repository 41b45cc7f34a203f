#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace mresim::io {

// A results file written through the HDF5 C API. Creating one truncates any file at that path.
//
// Paths are HDF5 paths ("/steps/field"; a path without a leading '/' is taken from the root).
// Missing intermediate groups are created, so callers never manage groups. Datasets are written
// once: writing to an existing dataset is an error (it would hide a bug that writes a step
// twice); attributes may be overwritten. Every numeric dataset carries a string attribute
// "unit" (SI; use "1" for dimensionless). Strings are UTF-8, variable length, so h5py reads them
// as Python str. Every failure throws std::runtime_error naming the file and the object.
//
// HDF5 as packaged in Debian is not thread-safe: write from one thread only.
class Hdf5File {
 public:
  explicit Hdf5File(const std::filesystem::path& file);
  ~Hdf5File();
  Hdf5File(Hdf5File&& other) noexcept;
  Hdf5File& operator=(Hdf5File&& other) noexcept;
  Hdf5File(const Hdf5File&) = delete;
  Hdf5File& operator=(const Hdf5File&) = delete;

  [[nodiscard]] const std::filesystem::path& path() const { return path_; }

  // Whether a group or dataset exists at `object_path` ("/" always exists).
  [[nodiscard]] bool exists(std::string_view object_path) const;
  // Creates the group and any missing parents; nothing happens if it exists.
  void create_group(std::string_view group_path);

  // Attributes on a group or dataset ("/" is the file's root group). A missing group is created.
  void write_string_attribute(std::string_view object_path, std::string_view name,
                              std::string_view value);
  void write_number_attribute(std::string_view object_path, std::string_view name, double value);
  void write_int_attribute(std::string_view object_path, std::string_view name, std::int64_t value);
  // One-dimensional attributes (H5MD's `version` [1, 1], a box's `boundary` per axis).
  void write_int_vector_attribute(std::string_view object_path, std::string_view name,
                                  const std::vector<std::int64_t>& values);
  void write_string_vector_attribute(std::string_view object_path, std::string_view name,
                                     const std::vector<std::string>& values);

  void write_vector(std::string_view dataset_path, const std::vector<double>& values,
                    std::string_view unit);
  // `unit` is stored only when not empty (counts and indices usually have none).
  void write_int_vector(std::string_view dataset_path, const std::vector<std::int64_t>& values,
                        std::string_view unit = {});
  // A rows x cols dataset from row-major data (row i is values[i*cols .. i*cols+cols-1]).
  void write_matrix(std::string_view dataset_path, std::size_t rows, std::size_t cols,
                    const std::vector<double>& row_major, std::string_view unit);
  // Any rank (e.g. steps x particles x 3), C order, dims.size() >= 1.
  void write_array(std::string_view dataset_path, const std::vector<std::size_t>& dims,
                   const std::vector<double>& c_order, std::string_view unit);
  // Integers of any rank (e.g. cells x 8 node indices), C order, no unit.
  void write_int_array(std::string_view dataset_path, const std::vector<std::size_t>& dims,
                       const std::vector<std::int64_t>& c_order);
  void write_string_vector(std::string_view dataset_path, const std::vector<std::string>& values);
  // Like write_array, stored in chunks of at most `chunk_rows` along the first dimension (the
  // other dimensions whole) and compressed with the shuffle filter + gzip level 1: shuffling
  // groups the bytes of neighbouring doubles (their exponents line up), so the fastest gzip
  // level already halves coordinates; higher levels gain a few percent at 1.5x the time
  // (docs/outputs-3d.md, "Compression of the node positions").
  void write_compressed_array(std::string_view dataset_path, const std::vector<std::size_t>& dims,
                              const std::vector<double>& c_order, std::string_view unit,
                              std::size_t chunk_rows);
  // A virtual dataset of sources.size() x item_dims: entry i is the whole dataset
  // sources[i].second of the file sources[i].first (a relative path: HDF5 looks it up beside
  // this file, so the directory can move). Costs no data; a missing source reads as NaN.
  void write_virtual_stack(std::string_view dataset_path, const std::vector<std::size_t>& item_dims,
                           const std::vector<std::pair<std::string, std::string>>& sources,
                           std::string_view unit);
  // A second name for an existing object (an HDF5 hard link): both names read the same data.
  void hard_link(std::string_view existing_path, std::string_view new_path);

  // Pushes buffered data to disk (useful before a long computation step).
  void flush();
  // Closes the file, reporting errors; the destructor closes silently. Further writes throw.
  void close();

 private:
  [[noreturn]] void fail(std::string_view action, std::string_view object_path) const;
  void require_open(std::string_view object_path) const;
  // Throws std::invalid_argument unless the product of dims is value_count.
  void check_shape(std::string_view dataset_path, const std::vector<std::size_t>& dims,
                   std::size_t value_count) const;
  // Opens the object (creating the group if it does not exist); returns an hid_t.
  [[nodiscard]] std::int64_t open_object(std::string_view object_path);
  // A scalar attribute when `count` is 0, otherwise a one-dimensional one of `count` values.
  void write_attribute(std::string_view object_path, std::string_view name, std::int64_t type,
                       const void* value, std::size_t count = 0);
  // `creation` is a dataset creation property list (hid_t; H5P_DEFAULT for contiguous storage).
  void write_dataset(std::string_view dataset_path, std::int64_t file_type,
                     std::int64_t memory_type, const std::vector<std::size_t>& dims,
                     const void* data, std::string_view unit, std::int64_t creation = 0);

  std::filesystem::path path_;
  std::int64_t file_ = -1;  // hid_t; kept as int64 so this header does not need hdf5.h
};

}  // namespace mresim::io
