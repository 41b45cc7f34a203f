#include "mresim/mess/protocols/kept_positions.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <string>
#include <utility>

namespace mresim::mess_protocol {

namespace {

std::runtime_error spill_error(const std::filesystem::path& directory, const std::string& what,
                               int error) {
  return std::runtime_error("scratch file for the kept positions in " + directory.string() + ": " +
                            what + ": " + std::strerror(error));
}

// Moves the `bytes` bytes of record `record` by io(offset in the record, count) (a pread or
// pwrite, which may move fewer), retrying on EINTR. Throws naming the directory, the operation and
// the reason (a full disk shows as "No space left on device").
template <class Io>
void transfer(const std::filesystem::path& directory, const char* what, std::int64_t record,
              std::int64_t bytes, Io&& io) {
  std::int64_t done = 0;
  while (done < bytes) {
    const ssize_t n = io(done, bytes - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      throw spill_error(directory,
                        std::string("cannot ") + what + " record " + std::to_string(record) + " (" +
                            std::to_string(bytes) + " bytes)",
                        n < 0 ? errno : ENOSPC);
    }
    done += n;
  }
}

}  // namespace

PositionsSpill::PositionsSpill(const std::filesystem::path& directory, Eigen::Index columns)
    : directory_(directory), columns_(columns) {
  // A unique name, then unlinked at once: the open descriptor keeps the file until it closes.
  std::string name = (directory / ".mresim-kept-positions-XXXXXX").string();
  fd_ = ::mkstemp(name.data());
  if (fd_ < 0) throw spill_error(directory_, "cannot create it", errno);
  ::unlink(name.c_str());
}

PositionsSpill::~PositionsSpill() {
  if (fd_ >= 0) ::close(fd_);
}

std::int64_t PositionsSpill::record_bytes() const {
  return static_cast<std::int64_t>(3 * sizeof(double)) * columns_;
}

std::int64_t PositionsSpill::write(const Eigen::Matrix3Xd& x) {
  if (x.cols() != columns_) {
    throw std::invalid_argument("PositionsSpill::write: " + std::to_string(x.cols()) +
                                " columns, expected " + std::to_string(columns_));
  }
  std::int64_t record = records_;
  if (!free_.empty()) {
    record = free_.back();
    free_.pop_back();
  } else {
    ++records_;
  }
  try {
    transfer(directory_, "write", record, record_bytes(), [&](std::int64_t at, std::int64_t n) {
      return ::pwrite(fd_, reinterpret_cast<const char*>(x.data()) + at,
                      static_cast<std::size_t>(n),
                      static_cast<off_t>(record * record_bytes() + at));
    });
  } catch (...) {
    free_.push_back(record);
    throw;
  }
  return record;
}

Eigen::Matrix3Xd PositionsSpill::read(std::int64_t record) const {
  Eigen::Matrix3Xd x(3, columns_);
  transfer(directory_, "read", record, record_bytes(), [&](std::int64_t at, std::int64_t n) {
    return ::pread(fd_, reinterpret_cast<char*>(x.data()) + at, static_cast<std::size_t>(n),
                   static_cast<off_t>(record * record_bytes() + at));
  });
  return x;
}

void PositionsSpill::release(std::int64_t record) { free_.push_back(record); }

// A parked array's record, released when the last KeptPositions sharing it lets it go.
struct KeptPositions::Record {
  Record(std::shared_ptr<PositionsSpill> s, std::int64_t n) : spill(std::move(s)), number(n) {}
  Record(const Record&) = delete;
  Record& operator=(const Record&) = delete;
  ~Record() { spill->release(number); }
  std::shared_ptr<PositionsSpill> spill;
  std::int64_t number;
};

std::uint64_t KeptPositions::new_version(const Eigen::Matrix3Xd& x) {
  static std::atomic<std::uint64_t> last{0};
  return x.cols() == 0 ? 0 : ++last;
}

KeptPositions& KeptPositions::operator=(Eigen::Matrix3Xd x) {
  record_.reset();
  memory_ = std::move(x);
  version_ = new_version(memory_);
  return *this;
}

Eigen::Index KeptPositions::cols() const {
  return record_ ? record_->spill->columns() : memory_.cols();
}

Eigen::Matrix3Xd KeptPositions::load() const {
  if (record_) return record_->spill->read(record_->number);
  return memory_;
}

Eigen::Matrix3Xd KeptPositions::take() {
  Eigen::Matrix3Xd x = record_ ? load() : std::move(memory_);
  record_.reset();
  memory_.resize(3, 0);
  version_ = 0;
  return x;
}

void KeptPositions::park(const std::shared_ptr<PositionsSpill>& spill) {
  if (record_ || memory_.cols() == 0) return;
  record_ = std::make_shared<const Record>(spill, spill->write(memory_));
  memory_.resize(3, 0);
}

}  // namespace mresim::mess_protocol
