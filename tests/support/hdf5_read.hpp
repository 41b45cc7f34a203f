#pragma once

// Minimal HDF5 readers for tests, written directly against the C API so that the tests do not
// trust the writer they check.

#include <hdf5.h>

#include <cstdint>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

namespace mresim::testing {

class Hdf5Reader {
 public:
  explicit Hdf5Reader(const std::filesystem::path& file)
      : file_(H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT)) {
    if (file_ < 0) throw std::runtime_error("cannot open " + file.string());
  }
  ~Hdf5Reader() { H5Fclose(file_); }
  Hdf5Reader(const Hdf5Reader&) = delete;
  Hdf5Reader& operator=(const Hdf5Reader&) = delete;

  std::vector<hsize_t> shape(const std::string& dataset) const {
    const hid_t ds = H5Dopen2(file_, dataset.c_str(), H5P_DEFAULT);
    const hid_t space = H5Dget_space(ds);
    std::vector<hsize_t> dims(static_cast<std::size_t>(H5Sget_simple_extent_ndims(space)));
    H5Sget_simple_extent_dims(space, dims.data(), nullptr);
    H5Sclose(space);
    H5Dclose(ds);
    return dims;
  }

  template <typename T>
  std::vector<T> values(const std::string& dataset, hid_t memory_type) const {
    std::size_t count = 1;
    for (const auto d : shape(dataset)) count *= d;
    std::vector<T> out(count);
    const hid_t ds = H5Dopen2(file_, dataset.c_str(), H5P_DEFAULT);
    if (count > 0) H5Dread(ds, memory_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, out.data());
    H5Dclose(ds);
    return out;
  }

  std::vector<double> doubles(const std::string& dataset) const {
    return values<double>(dataset, H5T_NATIVE_DOUBLE);
  }
  std::vector<std::int64_t> ints(const std::string& dataset) const {
    return values<std::int64_t>(dataset, H5T_NATIVE_INT64);
  }

  std::vector<std::string> strings(const std::string& dataset) const {
    const hid_t type = vlen_string();
    auto pointers = values<char*>(dataset, type);
    std::vector<std::string> out(pointers.begin(), pointers.end());
    const hid_t ds = H5Dopen2(file_, dataset.c_str(), H5P_DEFAULT);
    const hid_t space = H5Dget_space(ds);
    H5Dvlen_reclaim(type, space, H5P_DEFAULT, pointers.data());
    H5Sclose(space);
    H5Dclose(ds);
    H5Tclose(type);
    return out;
  }

  bool has_attribute(const std::string& object, const std::string& name) const {
    return H5Aexists_by_name(file_, object.c_str(), name.c_str(), H5P_DEFAULT) > 0;
  }

  std::string string_attribute(const std::string& object, const std::string& name) const {
    const hid_t attr =
        H5Aopen_by_name(file_, object.c_str(), name.c_str(), H5P_DEFAULT, H5P_DEFAULT);
    if (attr < 0) throw std::runtime_error("no attribute " + object + "@" + name);
    const hid_t type = vlen_string();
    char* text = nullptr;
    H5Aread(attr, type, &text);
    std::string out = text != nullptr ? text : "";
    H5free_memory(text);
    H5Tclose(type);
    H5Aclose(attr);
    return out;
  }

  template <typename T>
  T scalar_attribute(const std::string& object, const std::string& name, hid_t memory_type) const {
    const hid_t attr =
        H5Aopen_by_name(file_, object.c_str(), name.c_str(), H5P_DEFAULT, H5P_DEFAULT);
    if (attr < 0) throw std::runtime_error("no attribute " + object + "@" + name);
    T value{};
    H5Aread(attr, memory_type, &value);
    H5Aclose(attr);
    return value;
  }

 private:
  static hid_t vlen_string() {
    const hid_t type = H5Tcopy(H5T_C_S1);
    H5Tset_size(type, H5T_VARIABLE);
    H5Tset_cset(type, H5T_CSET_UTF8);
    return type;
  }

  hid_t file_;
};

}  // namespace mresim::testing
