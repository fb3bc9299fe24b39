#pragma once
// Room held on the disk of the daemon's state for what a full disk must not
// keep from being written (docs/SECURITY.md, "A full disk"): a stopped cut
// recorded as interrupted, an operator's cancel, the daemon's own start
// with the jobs it finds. A file of kBytes, allocated while the disk has
// room; its room is given back the moment a write of the job store finds
// the disk full (or the daemon starts on a disk without room), and it is
// made again once the disk has room for it and as much again.
//
// Threads: the service's strand only.

#include <cstdint>
#include <filesystem>

namespace rotafab::service {

class DiskReserve {
 public:
  // (SQLite records a transition in a few pages of its write-ahead log:
  // 8 MiB records thousands, where a full disk needs a few dozen.)
  static constexpr uint64_t kBytes = 8u << 20;

  explicit DiskReserve(std::filesystem::path file) : file_(std::move(file)) {}

  // Allocates the reserve unless it is there already; whether it is there now.
  bool hold();
  // Gives its room back to the disk; whether there was any to give.
  bool release();
  // Whether the disk has room, beside the reserve, for the reserve and as much again.
  [[nodiscard]] bool roomy() const;
  // Whether the disk has room, beside the reserve, for as much as the reserve.
  [[nodiscard]] bool enough() const;
  [[nodiscard]] const std::filesystem::path& file() const { return file_; }

  // Bytes an unprivileged user may still write on the disk that holds `path`.
  static uint64_t freeBytes(const std::filesystem::path& path);

 private:
  std::filesystem::path file_;
};

}  // namespace rotafab::service
