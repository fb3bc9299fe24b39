// docs/CONTRACT.md, "Command line": no partial output, files written whole
// or not at all. A file written atomically is either complete or absent (or
// still the old one), and the temporary file never outlives the call.

#include "toolpath/AtomicFile.h"

#include <grp.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "SheetFixture.h"

namespace rotafab::jobs::sheet_tests {
namespace {

std::vector<std::string> namesIn(const std::filesystem::path& folder) {
  std::vector<std::string> names;
  for (const auto& entry : std::filesystem::directory_iterator(folder)) names.push_back(entry.path().filename());
  std::sort(names.begin(), names.end());
  return names;
}

std::string messageOf(const std::function<void()>& action) {
  try {
    action();
  } catch (const std::runtime_error& error) {
    return error.what();
  }
  return "no error";
}

TEST(AtomicFile, WritesTheBytesAndNothingElse) {
  TempDir dir;
  const auto file = dir.path() / "sheet-001.eps";
  std::string bytes = "%!PS\n";
  bytes += std::string(1 << 20, 'x');  // larger than one write() usually takes
  bytes += std::string("\0end", 4);
  writeFileAtomically(file, bytes);
  EXPECT_EQ(readFile(file), bytes);
  EXPECT_EQ(namesIn(dir.path()), std::vector<std::string>{"sheet-001.eps"});
}

TEST(AtomicFile, ReplacesAnExistingFileWhole) {
  TempDir dir;
  const auto file = dir.write("manifest.json", std::string(1000, 'o'));
  writeFileAtomically(file, [](std::ostream& out) { out << "{\"version\": 1}\n"; });
  EXPECT_EQ(readFile(file), "{\"version\": 1}\n");
  EXPECT_EQ(namesIn(dir.path()), std::vector<std::string>{"manifest.json"});
}

TEST(AtomicFile, NewFilesGetTheUsualPermissions) {
  TempDir dir;
  const mode_t previous = ::umask(022);
  writeFileAtomically(dir.path() / "a.svg", "<svg/>");
  ::umask(027);
  writeFileAtomically(dir.path() / "b.svg", "<svg/>");
  ::umask(previous);
  struct stat a {
  }, b{};
  ASSERT_EQ(::stat((dir.path() / "a.svg").c_str(), &a), 0);
  ASSERT_EQ(::stat((dir.path() / "b.svg").c_str(), &b), 0);
  EXPECT_EQ(a.st_mode & 0777, 0644u);
  EXPECT_EQ(b.st_mode & 0777, 0640u);
}

TEST(AtomicFile, AFailedRenameLeavesNoTemporaryFile) {
  // The temporary file is written and synced, then cannot take the target's
  // place (a folder is in the way): it must be removed again.
  TempDir dir;
  std::filesystem::create_directories(dir.path() / "sheet-001.eps" / "inside");
  const std::string message = messageOf([&] { writeFileAtomically(dir.path() / "sheet-001.eps", "bytes"); });
  EXPECT_NE(message.find("cannot write " + (dir.path() / "sheet-001.eps").string()), std::string::npos) << message;
  EXPECT_EQ(message.find('\n'), std::string::npos);
  EXPECT_EQ(namesIn(dir.path()), std::vector<std::string>{"sheet-001.eps"});
  EXPECT_TRUE(std::filesystem::is_directory(dir.path() / "sheet-001.eps"));
}

TEST(AtomicFile, AMissingFolderIsNamed) {
  TempDir dir;
  const auto file = dir.path() / "no-such-folder" / "sheet-001.svg";
  const std::string message = messageOf([&] { writeFileAtomically(file, "bytes"); });
  EXPECT_NE(message.find("cannot write " + file.string()), std::string::npos) << message;
  EXPECT_NE(message.find("No such file or directory"), std::string::npos) << message;
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "no-such-folder"));
}

// Runs `action` in a child process as the unprivileged user "nobody" when we
// are root (root writes into any folder), else in this process; returns the
// message of the runtime_error it throws.
std::string messageAsUnprivilegedUser(const std::function<void()>& action) {
  if (::geteuid() != 0) return messageOf(action);
  int pipeEnds[2];
  if (::pipe(pipeEnds) != 0) return "pipe failed";
  const pid_t child = ::fork();
  if (child == 0) {
    ::close(pipeEnds[0]);
    const uid_t nobody = 65534;
    std::string message = "cannot drop privileges";
    if (::setgroups(0, nullptr) == 0 && ::setgid(nobody) == 0 && ::setuid(nobody) == 0) message = messageOf(action);
    (void)!::write(pipeEnds[1], message.data(), message.size());
    ::_exit(0);
  }
  ::close(pipeEnds[1]);
  std::string message;
  char buffer[512];
  for (ssize_t n; (n = ::read(pipeEnds[0], buffer, sizeof buffer)) > 0;) message.append(buffer, static_cast<size_t>(n));
  ::close(pipeEnds[0]);
  int status = 0;
  ::waitpid(child, &status, 0);
  return message;
}

TEST(AtomicFile, AnUnwritableFolderLeavesNothingBehind) {
  TempDir dir;
  const auto folder = dir.path() / "locked";
  std::filesystem::create_directories(folder);
  const auto old = folder / "sheet-001.dxf";
  std::ofstream(old) << "old";
  // Readable and searchable by everyone (the child may run as nobody),
  // writable by no one but root.
  std::filesystem::permissions(dir.path(), std::filesystem::perms::owner_all | std::filesystem::perms::others_read |
                                               std::filesystem::perms::others_exec);
  std::filesystem::permissions(folder, std::filesystem::perms::owner_read | std::filesystem::perms::owner_exec |
                                           std::filesystem::perms::others_read | std::filesystem::perms::others_exec);
  const std::string message = messageAsUnprivilegedUser([&] { writeFileAtomically(old, "new"); });
  std::filesystem::permissions(folder, std::filesystem::perms::owner_all);
  EXPECT_NE(message.find("cannot write " + old.string()), std::string::npos) << message;
  EXPECT_NE(message.find("Permission denied"), std::string::npos) << message;
  EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  EXPECT_EQ(readFile(old), "old");
  EXPECT_EQ(namesIn(folder), std::vector<std::string>{"sheet-001.dxf"});
}

TEST(AtomicFile, AFailingWriterKeepsTheOldFile) {
  TempDir dir;
  const auto file = dir.write("sheet-002.svg", "old sheet");
  EXPECT_THROW(writeFileAtomically(file,
                                   [](std::ostream& out) {
                                     out << "half a sheet";
                                     throw std::invalid_argument("path 3 has 1 point");
                                   }),
               std::invalid_argument);
  EXPECT_EQ(readFile(file), "old sheet");
  EXPECT_EQ(namesIn(dir.path()), std::vector<std::string>{"sheet-002.svg"});
}

}  // namespace
}  // namespace rotafab::jobs::sheet_tests
