#pragma once

// Node positions that a 3D run keeps from one step for a later one (protocol_runner.hpp: each
// field's latest state and its zero-load reference).
//
// A strain or stress run keeps two such arrays per field for its whole length, because its
// steps go through all fields at one load value before the next load value. That is 48 bytes
// per node and field: for the full-size Fig. 4.25 helix (993,168 nodes, 12 fields) 576 bytes
// per node, more than half of what its relaxation needs. So a run can park the arrays of the
// fields it is not working on in a scratch file (PositionsSpill) and read them back when their
// field comes up again: the doubles go to the file and come back bit for bit, so the results do
// not change (docs/performance.md, "Strain runs keep one field in memory").

#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <vector>

namespace mresim::mess_protocol {

// A scratch file of fixed-size records, each one 3 x `columns` array of doubles. The file is
// created in `directory` and unlinked at once, so that it never shows in a directory listing
// and its space is returned when the process ends, however it ends (killed or not): nothing
// is left behind. Records released are reused. Not for use from several threads at once.
class PositionsSpill {
 public:
  // Throws std::runtime_error naming the directory when the file cannot be created.
  PositionsSpill(const std::filesystem::path& directory, Eigen::Index columns);
  ~PositionsSpill();
  PositionsSpill(const PositionsSpill&) = delete;
  PositionsSpill& operator=(const PositionsSpill&) = delete;

  [[nodiscard]] Eigen::Index columns() const { return columns_; }
  // Writes x (columns() columns) into a free record and returns its number. Throws
  // std::runtime_error (the directory and the system's reason, e.g. a full disk).
  std::int64_t write(const Eigen::Matrix3Xd& x);
  // The array in record `record`, as written.
  [[nodiscard]] Eigen::Matrix3Xd read(std::int64_t record) const;
  // The record may be overwritten from now on.
  void release(std::int64_t record);
  // Records in the file (in use or free): its size is records() x 24 x columns() bytes.
  [[nodiscard]] std::int64_t records() const { return records_; }

 private:
  [[nodiscard]] std::int64_t record_bytes() const;

  std::filesystem::path directory_;  // for messages
  Eigen::Index columns_;
  int fd_ = -1;
  std::int64_t records_ = 0;
  std::vector<std::int64_t> free_;
};

// One kept array: none, in memory, or parked in a PositionsSpill. Copies of a parked array
// share its record (it is never written again; assigning a new array takes a new record), and
// the record is released when the last copy lets it go.
class KeptPositions {
 public:
  KeptPositions() = default;
  KeptPositions(Eigen::Matrix3Xd x)  // NOLINT(google-explicit-constructor): a value like x
      : memory_(std::move(x)), version_(new_version(memory_)) {}
  KeptPositions& operator=(Eigen::Matrix3Xd x);

  // Names the array's value: a new number, unique in the process, for each array given to it
  // (the constructor, assignment), shared by its copies and kept by park(); 0 when there is
  // none. A checkpoint rewrites an array only when its number changed (CheckpointWriter).
  [[nodiscard]] std::uint64_t version() const { return version_; }
  // Columns (nodes) of the array, parked or not; 0 when there is none.
  [[nodiscard]] Eigen::Index cols() const;
  [[nodiscard]] bool parked() const { return record_ != nullptr; }
  // A copy of the array (read from the file when parked); 3 x 0 when there is none.
  [[nodiscard]] Eigen::Matrix3Xd load() const;
  // The array, leaving none here (a move when it is in memory).
  Eigen::Matrix3Xd take();
  // Moves an array held in memory to `spill`, freeing its memory; nothing when there is none
  // or it is parked already.
  void park(const std::shared_ptr<PositionsSpill>& spill);

 private:
  struct Record;
  // A new version() for `x`, 0 for no array.
  static std::uint64_t new_version(const Eigen::Matrix3Xd& x);

  Eigen::Matrix3Xd memory_;
  std::shared_ptr<const Record> record_;
  std::uint64_t version_ = 0;
};

}  // namespace mresim::mess_protocol
