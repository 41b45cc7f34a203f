#include "mresim/io/hdf5_reader.hpp"

#include <fmt/format.h>
#include <hdf5.h>

#include <stdexcept>

#include "mresim/io/hdf5_silence.hpp"

namespace mresim::io {

namespace {

using QuietErrors = detail::SilenceHdf5Errors;

hid_t utf8_string_type() {
  const hid_t type = H5Tcopy(H5T_C_S1);
  H5Tset_size(type, H5T_VARIABLE);
  H5Tset_cset(type, H5T_CSET_UTF8);
  return type;
}

}  // namespace

Hdf5Reader::Hdf5Reader(const std::filesystem::path& file) : path_(file) {
  const QuietErrors quiet;
  file_ = H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  if (file_ < 0) fail("open", "/");
}

Hdf5Reader::~Hdf5Reader() {
  if (file_ >= 0) H5Fclose(file_);
}

void Hdf5Reader::fail(std::string_view action, std::string_view object_path) const {
  throw std::runtime_error(
      fmt::format("HDF5: cannot {} '{}' in '{}'", action, object_path, path_.string()));
}

bool Hdf5Reader::exists(std::string_view object_path) const {
  const QuietErrors quiet;
  const std::string p(object_path);
  if (p == "/") return true;
  // Check every prefix: H5Lexists fails on a path whose parent is missing.
  std::size_t pos = 0;
  while ((pos = p.find('/', pos + 1)) != std::string::npos) {
    if (H5Lexists(file_, p.substr(0, pos).c_str(), H5P_DEFAULT) <= 0) return false;
  }
  return H5Lexists(file_, p.c_str(), H5P_DEFAULT) > 0;
}

std::vector<std::size_t> Hdf5Reader::shape(std::string_view dataset_path) const {
  const QuietErrors quiet;
  const std::string p(dataset_path);
  const hid_t ds = H5Dopen2(file_, p.c_str(), H5P_DEFAULT);
  if (ds < 0) fail("open dataset", dataset_path);
  const hid_t space = H5Dget_space(ds);
  const int rank = H5Sget_simple_extent_ndims(space);
  std::vector<hsize_t> dims(static_cast<std::size_t>(rank > 0 ? rank : 0));
  if (rank > 0) H5Sget_simple_extent_dims(space, dims.data(), nullptr);
  H5Sclose(space);
  H5Dclose(ds);
  return {dims.begin(), dims.end()};
}

void Hdf5Reader::read(std::string_view dataset_path, std::int64_t memory_type, void* out,
                      std::size_t count) const {
  if (count == 0) return;
  const QuietErrors quiet;
  const std::string p(dataset_path);
  const hid_t ds = H5Dopen2(file_, p.c_str(), H5P_DEFAULT);
  if (ds < 0) fail("open dataset", dataset_path);
  const herr_t status = H5Dread(ds, memory_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, out);
  H5Dclose(ds);
  if (status < 0) fail("read", dataset_path);
}

namespace {
std::size_t element_count(const std::vector<std::size_t>& dims) {
  std::size_t n = 1;
  for (const std::size_t d : dims) n *= d;
  return n;
}
}  // namespace

std::vector<double> Hdf5Reader::doubles(std::string_view dataset_path) const {
  std::vector<double> out(element_count(shape(dataset_path)));
  read(dataset_path, H5T_NATIVE_DOUBLE, out.data(), out.size());
  return out;
}

std::vector<std::int64_t> Hdf5Reader::ints(std::string_view dataset_path) const {
  std::vector<std::int64_t> out(element_count(shape(dataset_path)));
  read(dataset_path, H5T_NATIVE_INT64, out.data(), out.size());
  return out;
}

std::vector<std::string> Hdf5Reader::strings(std::string_view dataset_path) const {
  std::vector<char*> pointers(element_count(shape(dataset_path)), nullptr);
  const hid_t type = utf8_string_type();
  read(dataset_path, type, pointers.data(), pointers.size());
  std::vector<std::string> out;
  out.reserve(pointers.size());
  for (char* s : pointers) {
    out.emplace_back(s != nullptr ? s : "");
    H5free_memory(s);
  }
  H5Tclose(type);
  return out;
}

std::int64_t Hdf5Reader::open_attribute(std::string_view object_path, std::string_view name) const {
  const std::string object(object_path);
  const std::string attribute(name);
  const hid_t attr =
      H5Aopen_by_name(file_, object.c_str(), attribute.c_str(), H5P_DEFAULT, H5P_DEFAULT);
  if (attr < 0) fail("open attribute " + attribute + " of", object_path);
  return attr;
}

std::string Hdf5Reader::string_attribute(std::string_view object_path,
                                         std::string_view name) const {
  const QuietErrors quiet;
  const hid_t attr = open_attribute(object_path, name);
  const hid_t type = utf8_string_type();
  char* text = nullptr;
  const herr_t status = H5Aread(attr, type, &text);
  std::string out = text != nullptr ? text : "";
  H5free_memory(text);
  H5Tclose(type);
  H5Aclose(attr);
  if (status < 0) fail("read attribute " + std::string(name) + " of", object_path);
  return out;
}

double Hdf5Reader::number_attribute(std::string_view object_path, std::string_view name) const {
  const QuietErrors quiet;
  const hid_t attr = open_attribute(object_path, name);
  double value = 0.0;
  const herr_t status = H5Aread(attr, H5T_NATIVE_DOUBLE, &value);
  H5Aclose(attr);
  if (status < 0) fail("read attribute " + std::string(name) + " of", object_path);
  return value;
}

std::int64_t Hdf5Reader::int_attribute(std::string_view object_path, std::string_view name) const {
  const QuietErrors quiet;
  const hid_t attr = open_attribute(object_path, name);
  std::int64_t value = 0;
  const herr_t status = H5Aread(attr, H5T_NATIVE_INT64, &value);
  H5Aclose(attr);
  if (status < 0) fail("read attribute " + std::string(name) + " of", object_path);
  return value;
}

}  // namespace mresim::io
