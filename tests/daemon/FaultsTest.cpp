// rotafabd under faults that are not an attacker's (docs/SECURITY.md, "A
// full disk"): the disk of its state filled during a cut, a start on a full
// disk, a plan that runs out of room; and a job no device can take, which
// must not hold back the jobs behind it.

#include <gtest/gtest.h>
#include <sys/mount.h>

#include <fstream>

#include "daemon/DaemonSupport.h"

namespace rotafab::test {
namespace {

using nlohmann::json;
namespace fs = std::filesystem;

// A small tmpfs at `at`, unmounted when it goes; false when mounting is not allowed (not root).
struct SmallDisk {
  fs::path at;
  bool mounted = false;
  SmallDisk(fs::path folder, const char* size) : at(std::move(folder)) {
    fs::create_directories(at);
    mounted = ::mount("tmpfs", at.c_str(), "tmpfs", 0, size) == 0;
  }
  ~SmallDisk() {
    if (mounted) ::umount2(at.c_str(), MNT_DETACH);
  }
  // Fills the disk to its last byte with `file`.
  void fill(const fs::path& file) const {
    std::ofstream out(file, std::ios::binary);
    const std::string piece(64 * 1024, 'f');
    while (out.write(piece.data(), piece.size())) out.flush();
    // (Its last blocks, in smaller pieces.)
    out.clear();
    for (int i = 0; i < 4096 && out.write(piece.data(), 512); ++i) out.flush();
  }
};

TEST(Faults, ACutWhoseStoreCannotBeWrittenStopsWithTheLaserOffAndIsInterrupted) {
  TempDir root;
  const SmallDisk disk(root.path() / "state", "size=48m");
  if (!disk.mounted) GTEST_SKIP() << "mounting a small tmpfs needs root (CI runs as root)";
  const fs::path witness = root.path() / "laser";
  Daemon daemon(root.path(), witnessedLaser(5, witness));
  daemon.start();
  const long long id = cuttingThreeSheets(daemon);
  ASSERT_NE(id, 0);
  const fs::path filler = root.path() / "state/filler";
  disk.fill(filler);
  const json stopped = daemon.waitForJob(
      id, [](const json& j) { return state(j) == "interrupted"; }, 30);
  ASSERT_EQ(state(stopped), "interrupted") << stopped.dump();
  EXPECT_NE(stopped.value("message", "").find("the disk that holds the daemon's state is full"), std::string::npos)
      << stopped.dump();
  EXPECT_TRUE(eventually([&] { return readFile(witness).ends_with("off\n"); }, 10)) << readFile(witness);
  // While the disk is full: the queue answers, a submission is refused saying why, and nothing cuts.
  EXPECT_EQ(daemon.client("jobs").status, 0);
  const CommandResult refused = daemon.client("submit " + quoted(threeSheets()));
  EXPECT_EQ(refused.status, 1);
  EXPECT_NE(refused.err.find("full"), std::string::npos) << refused.err;
  // Room again: the daemon takes submissions by itself, and the interruption was recorded.
  fs::remove(filler);
  EXPECT_TRUE(eventually([&] { return daemon.client("submit " + quoted(threeSheets())).status == 0; }, 20));
  daemon.kill9();
  daemon.start();
  EXPECT_EQ(state(daemon.job(id)), "interrupted");
  EXPECT_TRUE(readFile(witness).ends_with("off\n"));
}

TEST(Faults, ADaemonStartedOnAFullDiskAnswersAndCancels) {
  TempDir root;
  const SmallDisk disk(root.path() / "state", "size=48m");
  if (!disk.mounted) GTEST_SKIP() << "mounting a small tmpfs needs root (CI runs as root)";
  Daemon daemon(root.path());
  daemon.start();
  const long long id = daemon.clientJson("submit " + quoted(threeSheets()))["id"];
  ASSERT_EQ(state(daemon.waitForJob(id, [](const json& j) { return state(j) == "ready"; })), "ready");
  daemon.signal(SIGTERM);
  ASSERT_EQ(daemon.wait(30), 0);
  const fs::path filler = root.path() / "state/filler";
  disk.fill(filler);
  daemon.start();
  const CommandResult jobs = daemon.client("jobs");
  EXPECT_EQ(jobs.status, 0) << jobs.err;
  const CommandResult cancelled = daemon.client(fmt::format("cancel {}", id));
  EXPECT_EQ(cancelled.status, 0) << cancelled.err;
  EXPECT_EQ(state(daemon.waitForJob(
                id, [](const json& j) { return state(j) == "cancelled"; }, 20)),
            "cancelled");
  EXPECT_EQ(daemon.client("submit " + quoted(threeSheets())).status, 1);
  fs::remove(filler);
  EXPECT_TRUE(eventually([&] { return daemon.client("submit " + quoted(threeSheets())).status == 0; }, 20));
  daemon.kill9();
  daemon.start();
  EXPECT_EQ(state(daemon.job(id)), "cancelled");
}

TEST(Faults, APlanThatRunsOutOfDiskFailsSayingSoAndLeavesNoFiles) {
  TempDir root;
  // The spool on a disk of its own, with room for a mesh but not for its sheets.
  const SmallDisk disk(root.path() / "spool", "size=256k");
  if (!disk.mounted) GTEST_SKIP() << "mounting a small tmpfs needs root (CI runs as root)";
  Daemon daemon(root.path(), fmt::format("spool: {}\n", disk.at.string()));
  daemon.start();
  const json submitted =
      daemon.clientJson("submit " + quoted(kSource / "examples/soccer-ball.obj") + " --structure band --evaluations 1");
  ASSERT_TRUE(submitted.contains("id")) << submitted.dump();
  const long long id = submitted["id"];
  const json failed = daemon.waitForJob(
      id, [](const json& j) { return state(j) == "failed" || state(j) == "ready"; }, 60);
  EXPECT_EQ(state(failed), "failed") << failed.dump();
  EXPECT_NE(failed.value("message", "").find("the disk is full"), std::string::npos) << failed.dump();
  // Its half-written sheets are gone: the spool holds the mesh's entry only, and no sheet.
  for (const auto& entry : fs::recursive_directory_iterator(disk.at)) {
    EXPECT_EQ(entry.path().string().find("sheet-"), std::string::npos) << entry.path();
    EXPECT_EQ(entry.path().string().find("planned"), std::string::npos) << entry.path();
  }
  EXPECT_EQ(daemon.client("jobs").status, 0);
}

TEST(Faults, AJobNoDeviceCanTakeDoesNotHoldBackTheJobsBehindIt) {
  TempDir root;
  Daemon daemon(root.path(), "planners: 1\n");
  daemon.start();
  // The only device is a GRBL diode laser: a K40 job fails, and the one behind it is planned all the same.
  const long long k40 = daemon.clientJson("submit " + quoted(kSource / "examples/cube.obj") +
                                          " --structure band --machine k40-m2nano")["id"];
  const long long next =
      daemon.clientJson("submit " + quoted(kSource / "examples/cube.obj") + " --structure band --size 6in")["id"];
  const json refused = daemon.waitForJob(
      k40, [](const json& j) { return state(j) == "failed"; }, 30);
  EXPECT_EQ(state(refused), "failed") << refused.dump();
  EXPECT_NE(refused.value("message", "").find("no device has the machine profile k40-m2nano"), std::string::npos)
      << refused.dump();
  // No other submission comes to wake the queue.
  EXPECT_EQ(state(daemon.waitForJob(
                next, [](const json& j) { return state(j) == "ready"; }, 60)),
            "ready");
}

}  // namespace
}  // namespace rotafab::test
