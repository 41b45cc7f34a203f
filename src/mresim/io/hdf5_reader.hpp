#pragma once

// Reading back what Hdf5File wrote (checkpoints of long runs). Read-only, HDF5 C API; every
// failure throws std::runtime_error naming the file and the object. Single-threaded, like the
// writer.

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace mresim::io {

class Hdf5Reader {
 public:
  explicit Hdf5Reader(const std::filesystem::path& file);
  ~Hdf5Reader();
  Hdf5Reader(const Hdf5Reader&) = delete;
  Hdf5Reader& operator=(const Hdf5Reader&) = delete;

  [[nodiscard]] bool exists(std::string_view object_path) const;
  [[nodiscard]] std::vector<std::size_t> shape(std::string_view dataset_path) const;
  // All values in C order.
  [[nodiscard]] std::vector<double> doubles(std::string_view dataset_path) const;
  [[nodiscard]] std::vector<std::int64_t> ints(std::string_view dataset_path) const;
  [[nodiscard]] std::vector<std::string> strings(std::string_view dataset_path) const;

  [[nodiscard]] std::string string_attribute(std::string_view object_path,
                                             std::string_view name) const;
  [[nodiscard]] double number_attribute(std::string_view object_path, std::string_view name) const;
  [[nodiscard]] std::int64_t int_attribute(std::string_view object_path,
                                           std::string_view name) const;

 private:
  [[noreturn]] void fail(std::string_view action, std::string_view object_path) const;
  void read(std::string_view dataset_path, std::int64_t memory_type, void* out,
            std::size_t count) const;
  std::int64_t open_attribute(std::string_view object_path, std::string_view name) const;

  std::filesystem::path path_;
  std::int64_t file_ = -1;
};

}  // namespace mresim::io
