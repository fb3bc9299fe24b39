#pragma once
// The rule for an output folder (docs/CONTRACT.md, "Command line" and "make"):
// no partial set, no stale files. A job's files are all written into a hidden
// folder inside the target first (the same file system, whatever links lead
// there) and move in only when all are written, so that a failure or a cancel
// leaves the folder as it was (and a folder that was not there is not left
// behind). Each new file then replaces its old namesake in one rename, the one
// named last moving last, and only after that are the old job's files that the
// new one does not have (a stale sheet-009.eps beside a new 8-sheet job)
// removed.

#include <filesystem>
#include <functional>
#include <string>

namespace rotafab::jobs {

// Why `target` cannot be an output folder (it is a file, or a file stands
// where one of the folders above it would be), or "" when it can: asked
// before any work, so that a job is not built only to fail at the end.
std::string whyNotAnOutputFolder(const std::filesystem::path& target);

class OutputFolder {
 public:
  // Creates `target` if need be, and the hidden folder inside it. Throws
  // std::filesystem::filesystem_error when it cannot.
  explicit OutputFolder(std::filesystem::path target);
  // Unless committed: removes the hidden folder, and the target and the
  // folders created for it if they are empty. Never throws.
  ~OutputFolder();
  OutputFolder(const OutputFolder&) = delete;
  OutputFolder& operator=(const OutputFolder&) = delete;

  [[nodiscard]] const std::filesystem::path& target() const { return target_; }
  // Where the files are written.
  [[nodiscard]] const std::filesystem::path& staging() const { return staging_; }

  // Moves every file written into the target, `last` after the others (a
  // reader of the folder sees the old job's `last` until the new files are
  // all in), then removes the target's files that `ours` claims and that were
  // not written this time.
  void commit(const std::string& last, const std::function<bool(const std::string&)>& ours);

 private:
  void removeCreated() noexcept;

  std::filesystem::path target_, staging_;
  std::filesystem::path created_;  // the outermost folder this made, or empty
  bool committed_ = false;
};

}  // namespace rotafab::jobs
