#include "daemon/service/Spool.h"

#include <fcntl.h>
#include <fmt/format.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <random>
#include <sstream>
#include <stdexcept>
#include <system_error>

#include "jobs/AtomicFile.h"

namespace rotafab::service {
namespace fs = std::filesystem;
namespace {

constexpr std::string_view kIncoming = ".incoming-";

std::string randomName() {
  static thread_local std::mt19937_64 generator{std::random_device{}()};
  return fmt::format("{:016x}", generator());
}

}  // namespace

void syncFolder(const fs::path& folder) {
  const int fd = ::open(folder.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0)
    throw std::runtime_error(fmt::format("{}: cannot open the folder: {}", folder.string(), std::strerror(errno)));
  const int synced = ::fsync(fd);
  const int error = errno;
  ::close(fd);
  if (synced != 0) {
    throw std::runtime_error(fmt::format("{}: cannot sync the folder: {}", folder.string(), std::strerror(error)));
  }
}

Spool::Spool(fs::path folder) : folder_(std::move(folder)) {
  std::error_code error;
  fs::create_directories(folder_, error);
  if (error)
    throw std::runtime_error(fmt::format("{}: cannot create the spool: {}", folder_.string(), error.message()));
}

Spool::Entry Spool::begin() const {
  const std::string name = "job-" + randomName();
  fs::path temporary = folder_ / (std::string(kIncoming) + name);
  std::error_code error;
  fs::create_directory(temporary, error);
  if (error) {
    throw std::runtime_error(fmt::format("{}: cannot create a spool entry: {}", temporary.string(), error.message()));
  }
  return Entry(*this, std::move(temporary), name);
}

Spool::Entry::Entry(const Spool& spool, fs::path temporary, std::string name)
    : spool_(&spool), temporary_(std::move(temporary)), name_(std::move(name)) {}

Spool::Entry::Entry(Entry&& other) noexcept
    : spool_(other.spool_),
      temporary_(std::move(other.temporary_)),
      name_(std::move(other.name_)),
      committed_(other.committed_) {
  other.committed_ = true;  // the moved-from entry removes nothing
}

Spool::Entry::~Entry() {
  if (committed_) return;
  std::error_code ignored;
  fs::remove_all(temporary_, ignored);
}

void Spool::Entry::addFile(std::string_view name, std::string_view bytes) {
  jobs::writeFileAtomically(temporary_ / std::string(name), bytes);
}

void Spool::Entry::copyFolder(const fs::path& from) {
  std::error_code error;
  for (const fs::directory_entry& file : fs::directory_iterator(from, error)) {
    if (!file.is_regular_file()) continue;
    std::ifstream in(file.path(), std::ios::binary);
    std::ostringstream bytes;
    bytes << in.rdbuf();
    if (!in && !in.eof()) throw std::runtime_error(fmt::format("{}: cannot read the file", file.path().string()));
    addFile(file.path().filename().string(), bytes.str());
  }
  if (error) throw std::runtime_error(fmt::format("{}: cannot read the folder: {}", from.string(), error.message()));
}

std::string Spool::Entry::commit() {
  syncFolder(temporary_);
  const fs::path final = spool_->folder_ / name_;
  if (::rename(temporary_.c_str(), final.c_str()) != 0) {
    throw std::runtime_error(
        fmt::format("{}: cannot rename the spool entry: {}", final.string(), std::strerror(errno)));
  }
  committed_ = true;
  syncFolder(spool_->folder_);
  return name_;
}

size_t Spool::removeOrphans(const std::set<std::string>& named) const {
  size_t removed = 0;
  std::error_code error;
  for (const fs::directory_entry& entry : fs::directory_iterator(folder_, error)) {
    const std::string name = entry.path().filename().string();
    if (named.contains(name)) continue;
    if (!name.starts_with(kIncoming) && !name.starts_with("job-")) continue;
    std::error_code ignored;
    fs::remove_all(entry.path(), ignored);
    ++removed;
  }
  return removed;
}

}  // namespace rotafab::service
