// The daemon's smaller parts: the multipart form a browser or curl sends,
// the configuration's checks, the tokens' hashes, the spool's entries.

#include <gtest/gtest.h>
#include <sys/mount.h>

#include "daemon/service/DaemonConfig.h"
#include "daemon/service/Multipart.h"
#include "daemon/service/Spool.h"
#include "support/TestSupport.h"

namespace rotafab::service {
namespace {

using test::TempDir;

TEST(Multipart, TheFieldsAndTheFileOfAFormAreRead) {
  const std::string body =
      "--XyZ\r\nContent-Disposition: form-data; name=\"options\"\r\n\r\n[\"--structure\",\"band\"]\r\n"
      "--XyZ\r\nContent-Disposition: form-data; name=\"file\"; filename=\"cube.obj\"\r\n"
      "Content-Type: application/octet-stream\r\n\r\nv 0 0 0\r\n--not the boundary\r\n\r\n--XyZ--\r\n";
  ASSERT_EQ(multipartBoundary("multipart/form-data; boundary=XyZ"), "XyZ");
  ASSERT_EQ(multipartBoundary("Multipart/Form-Data; boundary=\"XyZ\""), "XyZ");
  EXPECT_FALSE(multipartBoundary("application/json"));
  const auto parts = parseMultipart(body, "XyZ");
  ASSERT_EQ(parts.size(), 2u);
  EXPECT_EQ(parts[0].name, "options");
  EXPECT_FALSE(parts[0].fileName);
  EXPECT_EQ(parts[0].bytes, "[\"--structure\",\"band\"]");
  EXPECT_EQ(parts[1].name, "file");
  EXPECT_EQ(parts[1].fileName, "cube.obj");
  EXPECT_EQ(parts[1].bytes, "v 0 0 0\r\n--not the boundary\r\n");
}

TEST(Multipart, AMalformedFormIsRefusedSayingWhat) {
  EXPECT_THROW(parseMultipart("no boundary at all", "XyZ"), std::invalid_argument);
  EXPECT_THROW(parseMultipart("--XyZ\r\nContent-Disposition: form-data; name=\"a\"\r\n\r\nunterminated", "XyZ"),
               std::invalid_argument);
  EXPECT_THROW(parseMultipart("--XyZ\r\nX-Other: 1\r\n\r\nbytes\r\n--XyZ--", "XyZ"), std::invalid_argument);
}

TEST(DaemonConfig, EveryKeyIsOptionalAndAMistakeNamesItsLineAndColumn) {
  TempDir dir;
  const auto empty = dir.write("empty.yaml", "");
  const DaemonConfig defaults = loadConfig(empty);
  ASSERT_EQ(defaults.devices.size(), 1u);
  EXPECT_TRUE(defaults.devices[0].uri.starts_with("sim:grbl"));
  const auto good = dir.write("good.yaml",
                              "state_dir: /tmp/somewhere\n"
                              "listen: [unix:/tmp/somewhere/d.sock, tcp://127.0.0.1:0]\n"
                              "devices:\n"
                              "  - {name: laser1, machine: grbl-diode-400, uri: \"sim:grbl\", auto_start: true}\n"
                              "  - {name: k40, uri: \"sim:m2nano\"}\n");
  const DaemonConfig config = loadConfig(good);
  EXPECT_EQ(config.stateDir, "/tmp/somewhere");
  EXPECT_EQ(config.listen.size(), 2u);
  ASSERT_EQ(config.devices.size(), 2u);
  EXPECT_TRUE(config.devices[0].autoStart);
  EXPECT_FALSE(config.devices[1].autoStart);
  const auto expectRefused = [&](const std::string& yaml, const std::string& message) {
    const auto file = dir.write("bad.yaml", yaml);
    try {
      loadConfig(file);
      ADD_FAILURE() << "accepted: " << yaml;
    } catch (const ConfigError& error) {
      EXPECT_EQ(std::string(error.what()), file.string() + ":" + message) << yaml;
    }
  };
  expectRefused("devices:\n  - {name: laser1}\n", "2:5: devices[0].uri: missing");
  expectRefused("devices:\n  - {name: a, uri: \"sim:grbl\", autostart: true}\n",
                "2:32: devices[0].autostart: unknown key (expected one of: name, machine, uri, material, auto_start)");
  expectRefused("listen: [http://0.0.0.0:80]\n",
                "1:10: listen[0]: expected unix:PATH or tcp://HOST:PORT, found 'http://0.0.0.0:80'");
  expectRefused(
      "listen: [tcp://0.0.0.0:8730]\n",
      "1:10: listen[0]: tcp://0.0.0.0:8730 is reachable from other machines: give tokens (rotafabd --hash-token)");
  expectRefused(
      "statedir: /tmp\n",
      "1:1: statedir: unknown key (expected one of: state_dir, store, host, spool, lease, listen, tokens, "
      "origins, devices, upload_limit, connection_limit, planners, header_timeout, body_timeout, plan_timeout, "
      "notify, units)");
  expectRefused("units: cm\n", "1:8: units: cm: expected mm or in");
  EXPECT_EQ(loadConfig(dir.write("units.yaml", "units: mm\n")).units, core::LengthUnit::millimetres());
  expectRefused("notify: {webhooks: [https://hooks.example/x]}\n",
                "1:21: notify.webhooks[0]: expected http://HOST[:PORT][/PATH], found 'https://hooks.example/x' (TLS "
                "is not supported: a receiver on the lab's network, or a relay beside the daemon)");
  expectRefused("notify: {mqtt: \"mqtt://broker:99999\"}\n",
                "1:16: notify.mqtt: expected mqtt://HOST[:PORT], found 'mqtt://broker:99999'");
  expectRefused("notify: {mqtt: mqtt://broker, topic: \"lab/#\"}\n",
                "1:38: notify.topic: expected a topic such as rotafab or lab/lasers, without # or +");
  expectRefused("notify: {webhook: [http://x/]}\n",
                "1:10: notify.webhook: unknown key (expected one of: webhooks, mqtt, topic)");
  expectRefused("host: cutter room\n",
                "1:7: host: expected a name of letters, digits, '.', '_' and '-', such as cutter-room-2");
  expectRefused("lease: 0.5\n", "1:8: lease: must be between 1 and 3600, not 0.5");
  expectRefused("devices: [{name: a, uri: x}, {name: a, uri: y}]\n",
                "1:37: devices[1].name: another device has this name");
  expectRefused(
      "tokens: [{name: alice, hash: plain}]\n",
      "1:30: tokens[0].hash: expected \"sha256$SALT$HEX\" (64 hex digits), as `rotafabd --hash-token` prints it");
  expectRefused("devices: [a\n", "2:1: syntax: end of sequence flow not found");
  expectRefused("origins: [rotafab.lab.example]\n",
                "1:11: origins[0]: expected the page's address as a browser shows it, scheme and host (and port), "
                "such as https://rotafab.lab.example; found 'rotafab.lab.example'");
  expectRefused("origins: [\"https://lab.example/page\"]\n",
                "1:11: origins[0]: expected the page's address as a browser shows it, scheme and host (and port), "
                "such as https://rotafab.lab.example; found 'https://lab.example/page'");
  EXPECT_EQ(loadConfig(dir.write("origins.yaml", "origins: [\"https://lab.example:8443/\"]\n")).origins,
            std::vector<std::string>{"https://lab.example:8443"});
  EXPECT_EQ(loadConfig(dir.write("plan.yaml", "plan_timeout: 90\n")).planTimeout, 90);
  EXPECT_EQ(defaults.planTimeout, 3600);
  const DaemonConfig shared = loadConfig(dir.write("shared.yaml", "host: room-2\nspool: /mnt/fab/spool\nlease: 4\n"));
  EXPECT_EQ(shared.host, "room-2");
  EXPECT_EQ(shared.spool, "/mnt/fab/spool");
  EXPECT_EQ(shared.lease, 4);
  EXPECT_EQ(defaults.lease, 10);
}

TEST(DaemonConfig, ATokenMatchesOnlyTheHashMadeFromIt) {
  const std::string hash = hashToken("s3cret", "0a1b2c3d");
  EXPECT_TRUE(hash.starts_with("sha256$0a1b2c3d$"));
  EXPECT_EQ(hash.size(), std::string("sha256$0a1b2c3d$").size() + 64);
  EXPECT_TRUE(tokenMatches("s3cret", hash));
  EXPECT_FALSE(tokenMatches("s3cres", hash));
  EXPECT_FALSE(tokenMatches("", hash));
  EXPECT_FALSE(tokenMatches("s3cret", "sha256$0a1b2c3d$" + std::string(64, '0')));
  EXPECT_FALSE(tokenMatches("s3cret", "garbage"));
  // The same token with another salt makes another hash.
  EXPECT_NE(hashToken("s3cret", "ffff"), hash);
}

TEST(Spool, AnEntryIsRemovedUnlessCommittedAndAFolderIsLinkedNotCopied) {
  TempDir dir;
  const Spool spool(dir.path() / "spool");
  std::string name;
  {
    auto entry = spool.begin();
    entry.addFile("cube.obj", "v 0 0 0\n");
    name = entry.commit();
  }
  EXPECT_EQ(test::readFile(spool.pathOf(name) / "cube.obj"), "v 0 0 0\n");
  {
    auto abandoned = spool.begin();
    abandoned.addFile("half.obj", "v 1");
    // Not committed: it goes with the entry.
  }
  size_t entries = 0;
  for (const auto& entry : std::filesystem::directory_iterator(spool.folder())) entries += entry.exists();
  EXPECT_EQ(entries, 1u);
  // What a kill leaves (a half-filled entry, a whole one no job names yet) goes at the next start.
  std::filesystem::create_directories(spool.folder() / "job-half");
  std::filesystem::create_directories(spool.folder() / "job-orphan");
  EXPECT_EQ(spool.removeOrphans({name}), 2u);
  EXPECT_TRUE(std::filesystem::exists(spool.pathOf(name) / "cube.obj"));
  // A planned folder's files are linked: the same bytes, none copied, and
  // they stay when the folder submitted is made again or removed.
  const auto planned = dir.path() / "planned";
  std::filesystem::create_directories(planned / "sub");
  test::TempDir scratch;
  std::ofstream(planned / "sheet-001.svg") << "<svg/>";
  auto entry = spool.begin();
  entry.addFolder(planned);
  const std::string linked = entry.commit();
  EXPECT_EQ(std::filesystem::hard_link_count(spool.pathOf(linked) / "sheet-001.svg"), 2u);
  EXPECT_FALSE(std::filesystem::exists(spool.pathOf(linked) / "sub"));
  std::filesystem::remove_all(planned);
  EXPECT_EQ(test::readFile(spool.pathOf(linked) / "sheet-001.svg"), "<svg/>");
}

TEST(Spool, AFullDiskRefusesTheEntryAndLeavesNothingHalfWritten) {
  TempDir dir;
  const auto small = dir.path() / "small";
  std::filesystem::create_directories(small);
  if (::mount("tmpfs", small.c_str(), "tmpfs", 0, "size=256k") != 0) {
    GTEST_SKIP() << "mounting a small tmpfs needs root (CI runs as root)";
  }
  struct Unmount {
    std::filesystem::path at;
    ~Unmount() { ::umount2(at.c_str(), MNT_DETACH); }
  } unmount{small};
  const Spool spool(small / "spool");
  auto kept = spool.begin();
  kept.addFile("small.obj", std::string(1000, 'v'));
  const std::string name = kept.commit();
  try {
    auto entry = spool.begin();
    entry.addFile("big.obj", std::string(1 << 20, 'v'));
    FAIL() << "a 1 MiB file fitted in 256 KiB";
  } catch (const std::runtime_error& error) {
    EXPECT_NE(std::string(error.what()).find("No space left on device"), std::string::npos) << error.what();
  }
  EXPECT_EQ(spool.removeOrphans({name}), 0u);  // the refused entry is gone already
  EXPECT_EQ(std::filesystem::file_size(spool.pathOf(name) / "small.obj"), 1000u);
}

}  // namespace
}  // namespace rotafab::service
