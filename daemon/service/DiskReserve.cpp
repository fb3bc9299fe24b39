#include "daemon/service/DiskReserve.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <sys/statvfs.h>
#include <unistd.h>

#include <cstdint>

namespace rotafab::service {

uint64_t DiskReserve::freeBytes(const std::filesystem::path& path) {
  struct statvfs disk {};
  if (::statvfs(path.c_str(), &disk) != 0) return UINT64_MAX;  // unknown: taken as room
  return static_cast<uint64_t>(disk.f_bavail) * disk.f_frsize;
}

bool DiskReserve::hold() {
  struct stat existing {};
  if (::stat(file_.c_str(), &existing) == 0 && static_cast<uint64_t>(existing.st_blocks) * 512 >= kBytes) return true;
  const int fd = ::open(file_.c_str(), O_WRONLY | O_CREAT | O_CLOEXEC, 0600);
  if (fd < 0) return false;
  const int failed = ::posix_fallocate(fd, 0, static_cast<off_t>(kBytes));
  const int synced = failed == 0 ? ::fsync(fd) : -1;
  ::close(fd);
  if (failed != 0 || synced != 0) {
    ::unlink(file_.c_str());
    return false;
  }
  return true;
}

bool DiskReserve::release() { return ::unlink(file_.c_str()) == 0; }

bool DiskReserve::roomy() const { return freeBytes(file_.parent_path()) >= 2 * kBytes; }

bool DiskReserve::enough() const { return freeBytes(file_.parent_path()) >= kBytes; }

}  // namespace rotafab::service
