#include "mresim/io/hdf5_file.hpp"

#include <fmt/format.h>
#include <hdf5.h>

#include <algorithm>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <type_traits>
#include <utility>

#include "mresim/io/hdf5_silence.hpp"

namespace mresim::io {

static_assert(std::is_same_v<hid_t, std::int64_t>, "Hdf5File stores hid_t as std::int64_t");

namespace {

// Closes an HDF5 identifier when it goes out of scope.
class Handle {
 public:
  using Closer = herr_t (*)(hid_t);
  Handle(hid_t id, Closer closer) : id_(id), closer_(closer) {}
  ~Handle() {
    if (id_ >= 0) closer_(id_);
  }
  Handle(Handle&& other) noexcept : id_(std::exchange(other.id_, -1)), closer_(other.closer_) {}
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
  Handle& operator=(Handle&&) = delete;
  [[nodiscard]] hid_t get() const { return id_; }
  [[nodiscard]] bool valid() const { return id_ >= 0; }

 private:
  hid_t id_;
  Closer closer_;
};

using detail::SilenceHdf5Errors;

// The innermost description on HDF5's error stack ("name already exists"), then clears it.
std::string last_hdf5_error() {
  std::string description;
  H5Ewalk2(
      H5E_DEFAULT, H5E_WALK_DOWNWARD,
      [](unsigned, const H5E_error2_t* error, void* out) -> herr_t {
        if (error->desc != nullptr && *error->desc != '\0') {
          *static_cast<std::string*>(out) = error->desc;
        }
        return 0;
      },
      &description);
  H5Eclear2(H5E_DEFAULT);
  return description.empty() ? std::string("HDF5 error") : description;
}

std::string absolute(std::string_view object_path) {
  // Built by appending: `"/" + std::string(...)` trips a false GCC 12 -Wrestrict warning.
  std::string full;
  if (object_path.empty() || object_path.front() != '/') full += '/';
  full += object_path;
  return full;
}

// A variable-length UTF-8 string type: h5py reads it as str, and there is no size limit.
Handle string_type() {
  Handle type(H5Tcopy(H5T_C_S1), H5Tclose);
  H5Tset_size(type.get(), H5T_VARIABLE);
  H5Tset_cset(type.get(), H5T_CSET_UTF8);
  return type;
}

}  // namespace

Hdf5File::Hdf5File(const std::filesystem::path& file) : path_(file) {
  const SilenceHdf5Errors silence;
  file_ = H5Fcreate(file.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
  if (file_ < 0) {
    throw std::runtime_error(
        fmt::format("cannot create HDF5 file '{}': {}", path_.string(), last_hdf5_error()));
  }
}

Hdf5File::~Hdf5File() {
  if (file_ >= 0) {
    const SilenceHdf5Errors silence;
    H5Fclose(file_);
  }
}

Hdf5File::Hdf5File(Hdf5File&& other) noexcept
    : path_(std::move(other.path_)), file_(std::exchange(other.file_, -1)) {}

Hdf5File& Hdf5File::operator=(Hdf5File&& other) noexcept {
  if (this != &other) {
    if (file_ >= 0) H5Fclose(file_);
    path_ = std::move(other.path_);
    file_ = std::exchange(other.file_, -1);
  }
  return *this;
}

void Hdf5File::fail(std::string_view action, std::string_view object_path) const {
  throw std::runtime_error(fmt::format("{} '{}' in '{}': {}", action, absolute(object_path),
                                       path_.string(), last_hdf5_error()));
}

void Hdf5File::require_open(std::string_view object_path) const {
  if (file_ < 0) {
    throw std::runtime_error(fmt::format("cannot write '{}' in '{}': the file is closed",
                                         absolute(object_path), path_.string()));
  }
}

bool Hdf5File::exists(std::string_view object_path) const {
  require_open(object_path);
  const SilenceHdf5Errors silence;
  const std::string full = absolute(object_path);
  // H5Lexists fails (rather than returning 0) when a parent is missing: test each prefix.
  for (std::size_t end = full.find('/', 1);; end = full.find('/', end + 1)) {
    const std::string prefix = full.substr(0, end);
    if (prefix.size() > 1 && H5Lexists(file_, prefix.c_str(), H5P_DEFAULT) <= 0) return false;
    if (end == std::string::npos) return true;
  }
}

void Hdf5File::create_group(std::string_view group_path) {
  require_open(group_path);
  if (exists(group_path)) return;
  const SilenceHdf5Errors silence;
  const Handle lcpl(H5Pcreate(H5P_LINK_CREATE), H5Pclose);
  H5Pset_create_intermediate_group(lcpl.get(), 1);
  const Handle group(
      H5Gcreate2(file_, absolute(group_path).c_str(), lcpl.get(), H5P_DEFAULT, H5P_DEFAULT),
      H5Gclose);
  if (!group.valid()) fail("cannot create group", group_path);
}

std::int64_t Hdf5File::open_object(std::string_view object_path) {
  if (!exists(object_path)) create_group(object_path);
  const SilenceHdf5Errors silence;
  const hid_t object = H5Oopen(file_, absolute(object_path).c_str(), H5P_DEFAULT);
  if (object < 0) fail("cannot open", object_path);
  return object;
}

void Hdf5File::write_attribute(std::string_view object_path, std::string_view name,
                               std::int64_t type, const void* value, std::size_t count) {
  require_open(object_path);
  const Handle object(open_object(object_path), H5Oclose);
  const SilenceHdf5Errors silence;
  const std::string attribute_name(name);
  const std::string where = fmt::format("{}@{}", absolute(object_path), name);
  if (H5Aexists(object.get(), attribute_name.c_str()) > 0 &&
      H5Adelete(object.get(), attribute_name.c_str()) < 0) {
    fail("cannot replace attribute", where);
  }
  const auto extent = static_cast<hsize_t>(count);
  const Handle space(count == 0 ? H5Screate(H5S_SCALAR) : H5Screate_simple(1, &extent, nullptr),
                     H5Sclose);
  const Handle attribute(
      H5Acreate2(object.get(), attribute_name.c_str(), type, space.get(), H5P_DEFAULT, H5P_DEFAULT),
      H5Aclose);
  if (!attribute.valid() || H5Awrite(attribute.get(), type, value) < 0) {
    fail("cannot write attribute", where);
  }
}

void Hdf5File::write_string_attribute(std::string_view object_path, std::string_view name,
                                      std::string_view value) {
  const Handle type = string_type();
  const std::string text(value);
  const char* c_text = text.c_str();
  write_attribute(object_path, name, type.get(), static_cast<const void*>(&c_text));
}

void Hdf5File::write_number_attribute(std::string_view object_path, std::string_view name,
                                      double value) {
  write_attribute(object_path, name, H5T_NATIVE_DOUBLE, &value);
}

void Hdf5File::write_int_attribute(std::string_view object_path, std::string_view name,
                                   std::int64_t value) {
  write_attribute(object_path, name, H5T_NATIVE_INT64, &value);
}

void Hdf5File::write_int_vector_attribute(std::string_view object_path, std::string_view name,
                                          const std::vector<std::int64_t>& values) {
  write_attribute(object_path, name, H5T_NATIVE_INT64, values.data(), values.size());
}

void Hdf5File::write_string_vector_attribute(std::string_view object_path, std::string_view name,
                                             const std::vector<std::string>& values) {
  std::vector<const char*> pointers;
  pointers.reserve(values.size());
  for (const auto& v : values) pointers.push_back(v.c_str());
  const Handle type = string_type();
  write_attribute(object_path, name, type.get(), pointers.data(), values.size());
}

void Hdf5File::write_dataset(std::string_view dataset_path, std::int64_t file_type,
                             std::int64_t memory_type, const std::vector<std::size_t>& dims,
                             const void* data, std::string_view unit, std::int64_t creation) {
  require_open(dataset_path);
  if (dims.empty()) {
    throw std::invalid_argument(fmt::format("dataset '{}' in '{}' needs at least one dimension",
                                            absolute(dataset_path), path_.string()));
  }
  if (exists(dataset_path)) {
    throw std::runtime_error(fmt::format("cannot write dataset '{}' in '{}': it already exists",
                                         absolute(dataset_path), path_.string()));
  }
  const std::vector<hsize_t> extent(dims.begin(), dims.end());
  const SilenceHdf5Errors silence;
  const Handle space(H5Screate_simple(static_cast<int>(extent.size()), extent.data(), nullptr),
                     H5Sclose);
  const Handle lcpl(H5Pcreate(H5P_LINK_CREATE), H5Pclose);
  H5Pset_create_intermediate_group(lcpl.get(), 1);
  const Handle dataset(H5Dcreate2(file_, absolute(dataset_path).c_str(), file_type, space.get(),
                                  lcpl.get(), creation, H5P_DEFAULT),
                       H5Dclose);
  if (!dataset.valid()) fail("cannot create dataset", dataset_path);
  const auto count = std::accumulate(dims.begin(), dims.end(), std::size_t{1},
                                     [](std::size_t a, std::size_t b) { return a * b; });
  // HDF5 rejects a null buffer even for zero elements; an empty dataset needs no write.
  if (count > 0 && H5Dwrite(dataset.get(), memory_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data) < 0) {
    fail("cannot write dataset", dataset_path);
  }
  if (!unit.empty()) write_string_attribute(dataset_path, "unit", unit);
}

void Hdf5File::write_vector(std::string_view dataset_path, const std::vector<double>& values,
                            std::string_view unit) {
  write_dataset(dataset_path, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, {values.size()}, values.data(),
                unit);
}

void Hdf5File::write_int_vector(std::string_view dataset_path,
                                const std::vector<std::int64_t>& values, std::string_view unit) {
  write_dataset(dataset_path, H5T_STD_I64LE, H5T_NATIVE_INT64, {values.size()}, values.data(),
                unit);
}

void Hdf5File::write_matrix(std::string_view dataset_path, std::size_t rows, std::size_t cols,
                            const std::vector<double>& row_major, std::string_view unit) {
  write_array(dataset_path, {rows, cols}, row_major, unit);
}

void Hdf5File::check_shape(std::string_view dataset_path, const std::vector<std::size_t>& dims,
                           std::size_t value_count) const {
  const auto count = std::accumulate(dims.begin(), dims.end(), std::size_t{1},
                                     [](std::size_t a, std::size_t b) { return a * b; });
  if (count != value_count) {
    throw std::invalid_argument(fmt::format(
        "dataset '{}' in '{}': shape [{}] needs {} values, got {}", absolute(dataset_path),
        path_.string(), fmt::join(dims, ", "), count, value_count));
  }
}

void Hdf5File::write_array(std::string_view dataset_path, const std::vector<std::size_t>& dims,
                           const std::vector<double>& c_order, std::string_view unit) {
  check_shape(dataset_path, dims, c_order.size());
  write_dataset(dataset_path, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, dims, c_order.data(), unit);
}

void Hdf5File::write_int_array(std::string_view dataset_path, const std::vector<std::size_t>& dims,
                               const std::vector<std::int64_t>& c_order) {
  check_shape(dataset_path, dims, c_order.size());
  write_dataset(dataset_path, H5T_STD_I64LE, H5T_NATIVE_INT64, dims, c_order.data(), {});
}

void Hdf5File::write_string_vector(std::string_view dataset_path,
                                   const std::vector<std::string>& values) {
  std::vector<const char*> pointers;
  pointers.reserve(values.size());
  for (const auto& v : values) pointers.push_back(v.c_str());
  const Handle type = string_type();
  write_dataset(dataset_path, type.get(), type.get(), {values.size()}, pointers.data(), {});
}

void Hdf5File::write_compressed_array(std::string_view dataset_path,
                                      const std::vector<std::size_t>& dims,
                                      const std::vector<double>& c_order, std::string_view unit,
                                      std::size_t chunk_rows) {
  check_shape(dataset_path, dims, c_order.size());
  // A chunk must not be empty and no dimension may be 0 in a chunked layout's chunk shape;
  // an empty dataset is written contiguous (there is nothing to compress).
  if (dims.empty() || c_order.empty() || chunk_rows == 0) {
    write_array(dataset_path, dims, c_order, unit);
    return;
  }
  std::vector<hsize_t> chunk(dims.begin(), dims.end());
  chunk[0] = std::min<hsize_t>(chunk[0], chunk_rows);
  const SilenceHdf5Errors silence;
  const Handle creation(H5Pcreate(H5P_DATASET_CREATE), H5Pclose);
  if (H5Pset_chunk(creation.get(), static_cast<int>(chunk.size()), chunk.data()) < 0 ||
      H5Pset_shuffle(creation.get()) < 0 || H5Pset_deflate(creation.get(), 1) < 0) {
    fail("cannot set up compression for", dataset_path);
  }
  write_dataset(dataset_path, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, dims, c_order.data(), unit,
                creation.get());
}

void Hdf5File::write_virtual_stack(std::string_view dataset_path,
                                   const std::vector<std::size_t>& item_dims,
                                   const std::vector<std::pair<std::string, std::string>>& sources,
                                   std::string_view unit) {
  require_open(dataset_path);
  if (exists(dataset_path)) {
    throw std::runtime_error(fmt::format("cannot write dataset '{}' in '{}': it already exists",
                                         absolute(dataset_path), path_.string()));
  }
  std::vector<hsize_t> extent = {sources.size()};
  extent.insert(extent.end(), item_dims.begin(), item_dims.end());
  const std::vector<hsize_t> item(item_dims.begin(), item_dims.end());
  const SilenceHdf5Errors silence;
  const Handle space(H5Screate_simple(static_cast<int>(extent.size()), extent.data(), nullptr),
                     H5Sclose);
  const Handle source_space(H5Screate_simple(static_cast<int>(item.size()), item.data(), nullptr),
                            H5Sclose);
  const Handle creation(H5Pcreate(H5P_DATASET_CREATE), H5Pclose);
  const double fill = std::numeric_limits<double>::quiet_NaN();
  H5Pset_fill_value(creation.get(), H5T_NATIVE_DOUBLE, &fill);
  std::vector<hsize_t> start(extent.size(), 0);
  std::vector<hsize_t> count = extent;
  count[0] = 1;
  for (std::size_t i = 0; i < sources.size(); ++i) {
    start[0] = i;
    if (H5Sselect_hyperslab(space.get(), H5S_SELECT_SET, start.data(), nullptr, count.data(),
                            nullptr) < 0 ||
        H5Pset_virtual(creation.get(), space.get(), sources[i].first.c_str(),
                       sources[i].second.c_str(), source_space.get()) < 0) {
      fail("cannot map '" + sources[i].first + "' into", dataset_path);
    }
  }
  H5Sselect_all(space.get());
  const Handle lcpl(H5Pcreate(H5P_LINK_CREATE), H5Pclose);
  H5Pset_create_intermediate_group(lcpl.get(), 1);
  const Handle dataset(H5Dcreate2(file_, absolute(dataset_path).c_str(), H5T_IEEE_F64LE,
                                  space.get(), lcpl.get(), creation.get(), H5P_DEFAULT),
                       H5Dclose);
  if (!dataset.valid()) fail("cannot create virtual dataset", dataset_path);
  if (!unit.empty()) write_string_attribute(dataset_path, "unit", unit);
}

void Hdf5File::hard_link(std::string_view existing_path, std::string_view new_path) {
  require_open(new_path);
  const SilenceHdf5Errors silence;
  const Handle lcpl(H5Pcreate(H5P_LINK_CREATE), H5Pclose);
  H5Pset_create_intermediate_group(lcpl.get(), 1);
  if (H5Lcreate_hard(file_, absolute(existing_path).c_str(), file_, absolute(new_path).c_str(),
                     lcpl.get(), H5P_DEFAULT) < 0) {
    fail("cannot link to '" + absolute(existing_path) + "' as", new_path);
  }
}

void Hdf5File::flush() {
  require_open("/");
  const SilenceHdf5Errors silence;
  if (H5Fflush(file_, H5F_SCOPE_GLOBAL) < 0) fail("cannot flush", "/");
}

void Hdf5File::close() {
  if (file_ < 0) return;
  const SilenceHdf5Errors silence;
  const herr_t status = H5Fclose(std::exchange(file_, -1));
  if (status < 0) {
    throw std::runtime_error(
        fmt::format("cannot close HDF5 file '{}': {}", path_.string(), last_hdf5_error()));
  }
}

}  // namespace mresim::io
