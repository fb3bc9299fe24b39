#pragma once
// The daemon's spool: one folder per job under the state directory, for the
// mesh that was uploaded and the sheets planned from it. A job's row may
// point at its folder only once every byte in it is on disk: an entry is
// filled under a temporary name, each file written and fsynced
// (jobs/AtomicFile.h), then renamed to its final name and the spool's own
// folder fsynced, so that after a kill or a power cut a folder with a final
// name is whole. What a kill leaves between the rename and the row (a
// folder no job names) is removed at the next start.

#include <filesystem>
#include <set>
#include <string>
#include <string_view>

namespace rotafab::service {

class Spool {
 public:
  // Creates the folder if need be; throws std::runtime_error naming it.
  explicit Spool(std::filesystem::path folder);

  // An entry being filled; removed unless committed.
  class Entry {
   public:
    Entry(const Entry&) = delete;
    Entry& operator=(const Entry&) = delete;
    Entry(Entry&& other) noexcept;
    ~Entry();
    // Writes one file into the entry, durably. Throws std::runtime_error ("... the disk is full").
    void addFile(std::string_view name, std::string_view bytes);
    // Copies the files of a folder (not its subfolders) into the entry, durably.
    void copyFolder(const std::filesystem::path& from);
    [[nodiscard]] const std::filesystem::path& folder() const { return temporary_; }
    // Gives the entry its final name, durably; returns that name (relative to the spool).
    std::string commit();

   private:
    friend class Spool;
    Entry(const Spool& spool, std::filesystem::path temporary, std::string name);
    const Spool* spool_;
    std::filesystem::path temporary_;
    std::string name_;
    bool committed_ = false;
  };

  // A new entry, "job-<random>".
  Entry begin() const;
  [[nodiscard]] std::filesystem::path pathOf(const std::string& name) const { return folder_ / name; }
  [[nodiscard]] const std::filesystem::path& folder() const { return folder_; }
  // Removes half-filled entries and folders no job names; returns how many.
  size_t removeOrphans(const std::set<std::string>& named) const;

 private:
  std::filesystem::path folder_;
};

// fsync of a folder, which makes the names in it (a rename) durable.
void syncFolder(const std::filesystem::path& folder);

}  // namespace rotafab::service
