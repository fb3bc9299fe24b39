#include "jobs/OutputFolder.h"

#include <fmt/format.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <set>

namespace rotafab::jobs {
namespace {

// Two jobs of one process (a daemon's) may write into one folder at once.
std::atomic<unsigned> stagings{0};

}  // namespace

std::string whyNotAnOutputFolder(const std::filesystem::path& target) {
  std::error_code error;
  auto full = std::filesystem::absolute(target, error).lexically_normal();
  if (error) return error.message();
  if (full.filename().empty()) full = full.parent_path();  // "dir/"
  for (std::filesystem::path p = full;; p = p.parent_path()) {
    const auto status = std::filesystem::status(p, error);
    if (status.type() == std::filesystem::file_type::directory) {
      if (::access(p.c_str(), W_OK | X_OK) != 0) {
        return fmt::format("cannot write in {}: {}", p.string(), std::strerror(errno));
      }
      return "";
    }
    if (status.type() != std::filesystem::file_type::not_found && status.type() != std::filesystem::file_type::none) {
      return p == full ? "is a file, not a folder: name a folder (it is made if it is missing)"
                       : fmt::format("{} is a file, so no folder can be made inside it", p.string());
    }
    if (p == p.parent_path()) return "";
  }
}

OutputFolder::OutputFolder(std::filesystem::path target) : target_(std::move(target)) {
  if (target_.filename().empty()) target_ = target_.parent_path();  // "dir/"
  // The folders to make, outermost last, on the path as it really runs ("a/../b" is b).
  const auto full = std::filesystem::absolute(target_).lexically_normal();
  for (std::filesystem::path p = full; !p.empty() && !std::filesystem::exists(p); p = p.parent_path()) {
    created_ = p;
    if (p == p.parent_path()) break;
  }
  try {
    std::filesystem::create_directories(target_);
    staging_ = target_ / fmt::format(".rotafab-partial-{}-{}", ::getpid(), stagings++);
    std::filesystem::remove_all(staging_);
    std::filesystem::create_directories(staging_);
  } catch (...) {
    removeCreated();
    throw;
  }
}

void OutputFolder::removeCreated() noexcept {
  if (created_.empty()) return;
  // Up from the target to the outermost folder made for it, each only if empty.
  std::error_code ignored;
  for (auto p = std::filesystem::absolute(target_, ignored).lexically_normal();; p = p.parent_path()) {
    if (!std::filesystem::remove(p, ignored) || p == created_ || p == p.parent_path()) break;
  }
}

OutputFolder::~OutputFolder() {
  std::error_code ignored;
  if (!staging_.empty()) std::filesystem::remove_all(staging_, ignored);
  if (!committed_) removeCreated();
}

void OutputFolder::commit(const std::string& last, const std::function<bool(const std::string&)>& ours) {
  std::set<std::string> written;
  for (const auto& entry : std::filesystem::directory_iterator(staging_)) {
    written.insert(entry.path().filename().string());
  }
  for (const std::string& name : written) {
    if (name != last) std::filesystem::rename(staging_ / name, target_ / name);
  }
  if (written.count(last)) std::filesystem::rename(staging_ / last, target_ / last);
  committed_ = true;
  for (const auto& entry : std::filesystem::directory_iterator(target_)) {
    const std::string name = entry.path().filename().string();
    if (entry.is_regular_file() && ours(name) && !written.count(name)) std::filesystem::remove(entry.path());
  }
}

}  // namespace rotafab::jobs
