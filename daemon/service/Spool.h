#pragma once
// The daemon's spool: one folder per job under the state directory, for the
// mesh that was uploaded and the sheets planned from it. A job's row may
// point at its folder only once every byte in it is on disk: an entry is
// filled, then the file system is synced (syncfs: one journal commit for
// every file and name in the entry, where an fsync of each would cost one
// each), and only then does the store get the row. A folder no row names is
// one a kill or a failure left before its row: it is removed when the entry
// fails, and at the next start. A planned folder's files are hard-linked
// into the entry where the file system allows it (a `make` output is
// replaced file by file, by rename, never written in place, so a link keeps
// the sheets as submitted), and copied otherwise.

#include <filesystem>
#include <set>
#include <string>
#include <string_view>
#include <vector>

namespace rotafab::service {

class Spool {
 public:
  // Creates the folder if need be; throws std::runtime_error naming it.
  // `owner`: the host whose entries these are, in a spool several hosts
  // share (each entry's name ends in "@owner", and a host removes only its own orphans).
  explicit Spool(std::filesystem::path folder, std::string owner = "");

  // An entry being filled; removed unless committed.
  class Entry {
   public:
    Entry(const Entry&) = delete;
    Entry& operator=(const Entry&) = delete;
    Entry(Entry&& other) noexcept;
    ~Entry();
    // A file of the entry written a piece at a time, as its bytes arrive (an upload).
    class File {
     public:
      File(File&& other) noexcept;
      File(const File&) = delete;
      File& operator=(const File&) = delete;
      ~File();
      // Throws std::runtime_error naming the file and why ("No space left on device").
      void write(std::string_view bytes);
      // Closes it; throws as write() when the file system says so only then.
      void close();

     private:
      friend class Entry;
      File(int fd, std::filesystem::path path) : fd_(fd), path_(std::move(path)) {}
      int fd_;
      std::filesystem::path path_;
    };
    // A new file in the entry. Throws std::runtime_error naming it.
    File create(std::string_view name);
    // Writes one file into the entry. Throws std::runtime_error naming it ("No space left on device").
    void addFile(std::string_view name, std::string_view bytes);
    // A copy of `from`, read and written a piece at a time (never whole in memory). Throws as addFile.
    void copyFile(std::string_view name, const std::filesystem::path& from);
    // The files of a folder (not its subfolders), linked or copied into the entry.
    void addFolder(const std::filesystem::path& from);
    [[nodiscard]] const std::filesystem::path& folder() const { return folder_; }
    // Syncs the entry to disk; returns its name (relative to the spool), for the job's row.
    std::string commit();
    // Syncs all of them with one syncfs (they are on one file system); throws as commit().
    static void commitAll(const std::vector<Entry*>& entries);
    [[nodiscard]] const std::string& name() const { return name_; }

   private:
    friend class Spool;
    Entry(const Spool& spool, std::filesystem::path folder, std::string name);
    const Spool* spool_;
    std::filesystem::path folder_;
    std::string name_;
    bool committed_ = false;
  };

  // A new entry, "job-<random>" (then "@owner" when there is one).
  Entry begin() const;
  [[nodiscard]] std::filesystem::path pathOf(const std::string& name) const { return folder_ / name; }
  [[nodiscard]] const std::filesystem::path& folder() const { return folder_; }
  // Removes the folders no job names; returns how many.
  size_t removeOrphans(const std::set<std::string>& named) const;

 private:
  std::filesystem::path folder_;
  std::string owner_;
};

// fsync of a folder, which makes the names in it (a rename) durable.
void syncFolder(const std::filesystem::path& folder);

}  // namespace rotafab::service
