#include "devices/sim/M2NanoSimulator.h"

#include <fmt/format.h>
#include <linux/usbdevice_fs.h>
#include <sys/ioctl.h>
#include <umockdev.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstddef>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <fstream>
#include <mutex>
#include <stdexcept>

#include "devices/m2nano/Lhymicro.h"

namespace rotafab::devices::sim {
namespace {

using Clock = std::chrono::steady_clock;

constexpr const char* kDeviceNode = "/dev/bus/usb/001/004";

// The CH341 in parallel mode as sysfs shows it (descriptors: device, one
// configuration, interface 0 with bulk endpoints 0x82 in and 0x02 out and an
// interrupt endpoint 0x81), in umockdev's format.
constexpr const char* kDevice =
    "P: /devices/pci0000:00/0000:00:14.0/usb1/1-3\n"
    "N: bus/usb/001/004\n"
    "E: DEVNAME=/dev/bus/usb/001/004\n"
    "E: DEVTYPE=usb_device\n"
    "E: SUBSYSTEM=usb\n"
    "E: BUSNUM=001\n"
    "E: DEVNUM=004\n"
    "A: busnum=1\n"
    "A: devnum=4\n"
    "A: idVendor=1a86\n"
    "A: idProduct=5512\n"
    "A: product=USB2.0-Print\n"
    "A: bDeviceClass=ff\n"
    "A: bNumConfigurations=1\n"
    "A: bConfigurationValue=1\n"
    "A: speed=12\n"
    "H: descriptors=12011001FF000008861A12550403000200010902270001010080300904000003FF01020007058202200000070502022000"
    "0007058103080001\n";

constexpr uint8_t kUrbControl = 2, kUrbBulk = 3;

struct Urb {
  UMockdevIoctlData* urb = nullptr;     // our reference to the client's usbdevfs_urb
  UMockdevIoctlData* buffer = nullptr;  // and to its buffer (owned by `urb` too)
  usbdevfs_urb* fields() const { return reinterpret_cast<usbdevfs_urb*>(urb->data); }
};

void release(Urb& u) {
  if (u.buffer) g_object_unref(u.buffer);
  if (u.urb) g_object_unref(u.urb);
  u = {};
}

}  // namespace

struct M2NanoSimulator::State {
  explicit State(M2NanoSimulatorOptions o) : options(o), board(o.board), last(Clock::now()) {}

  M2NanoSimulatorOptions options;
  mutable std::mutex mutex;
  LhymicroBoard board;
  Clock::time_point last;
  M2NanoSimulatorRecord counts;  // initialised, packets, payloads, status requests

  // USB side: URBs the board has finished (to be reaped) and reads waiting for a reply.
  std::deque<Urb> done, reads;
  std::deque<std::array<uint8_t, 6>> replies;
  bool rejected = false;  // the last packet failed its check: 207 until the next one
  bool checking = false;  // a packet just arrived: the first status after it is 238
  int finishedReads = 0;  // status requests answered 236 since the job finished
  Clock::time_point finishedSince{};
  bool wasFinished = false;

  // Faults.
  bool unplugged = false, muted = false, garbage = false, power = false;
  size_t corrupt = 0;
  size_t faultAt = 0;
  std::function<void(M2NanoSimulator&)> fault;

  UMockdevTestbed* testbed = nullptr;
  UMockdevIoctlBase* handler = nullptr;
  M2NanoSimulator* owner = nullptr;

  void advance() {
    const auto now = Clock::now();
    board.advance(std::chrono::duration<double>(now - last).count() * options.timeScale);
    last = now;
  }

  int status() {
    if (rejected) return m2nano::kCrcError;
    if (power) return m2nano::kPowerFault;
    if (checking) {
      checking = false;
      return m2nano::kBusy;
    }
    if (board.full()) return m2nano::kBusy;
    // "Finished" for a while after a job (or a home) ends: read at least
    // twice and for a quarter of a second, as hosts that poll slowly need it.
    if (board.finished()) {
      if (!wasFinished) wasFinished = true, finishedReads = 0, finishedSince = Clock::now();
      if (finishedReads < 2 || Clock::now() - finishedSince < std::chrono::milliseconds(250)) {
        ++finishedReads;
        return m2nano::kFinished;
      }
    } else {
      wasFinished = false;
    }
    return m2nano::kOk;
  }

  void answerStatus() {
    ++counts.statusRequests;
    if (muted) return;
    std::array<uint8_t, 6> reply = {0xFF, static_cast<uint8_t>(status()), 0x6F, 0x08, 0x13, 0x00};
    if (garbage) reply[1] = 0x31, garbage = false;
    replies.push_back(reply);
  }

  void takePacket(const uint8_t* bytes) {
    checking = true;
    wasFinished = false;  // a "finished" from now on is a new one
    bool good = bytes[0] == 0xA6 && bytes[1] == 0x00 && bytes[32] == 0xA6 && m2nano::crc8(bytes + 2, 30) == bytes[33];
    if (good && corrupt > 0) --corrupt, good = false;  // as if a byte flipped on the way
    rejected = !good;
    if (!good) {
      ++counts.packetsRejected;
      return;
    }
    std::array<uint8_t, 30> payload{};
    std::copy(bytes + 2, bytes + 32, payload.begin());
    board.accept(payload);
    ++counts.packetsAccepted;
    counts.payloads.emplace_back(payload.begin(), payload.end());
  }

  // An OUT or control transfer, done at once.
  void transfer(Urb& u) {
    usbdevfs_urb* urb = u.fields();
    uint8_t* data = u.buffer ? u.buffer->data : nullptr;
    const int length = urb->buffer_length;
    urb->status = 0;
    urb->actual_length = 0;
    if (urb->type == kUrbControl && data && length >= 8) {
      const uint8_t requestType = data[0], request = data[1];
      if (requestType == 0x40 && request == 0xB1) {  // parallel port init (EPP)
        counts.initialised = true;
      } else if (requestType == 0xC0 && request == 0x5F && length >= 10) {  // chip version
        data[8] = 0x30, data[9] = 0x00;
        urb->actual_length = 2;
      } else {
        urb->status = -EPIPE;  // a stall, as the chip answers requests it does not know
      }
    } else if (urb->type == kUrbBulk && urb->endpoint == 0x02 && data) {
      if (length == 1 && data[0] == 0xA0) {
        answerStatus();
      } else if (length == 34) {
        takePacket(data);
      } else {
        ++counts.packetsRejected;
        rejected = true;
      }
      urb->actual_length = length;
    } else {
      urb->status = -EPIPE;
    }
  }

  void answerReads() {
    while (!reads.empty() && !replies.empty()) {
      Urb u = reads.front();
      reads.pop_front();
      usbdevfs_urb* urb = u.fields();
      const auto& reply = replies.front();
      const size_t n = std::min<size_t>(reply.size(), static_cast<size_t>(std::max(urb->buffer_length, 0)));
      if (u.buffer) std::memcpy(u.buffer->data, reply.data(), n);
      urb->status = 0;
      urb->actual_length = static_cast<int>(n);
      replies.pop_front();
      done.push_back(u);
    }
  }

  static void complete(UMockdevIoctlClient* client, long result, int error) {
    umockdev_ioctl_client_complete(client, result, error);
  }

  // Runs on umockdev's worker thread, for each usbfs request of the driver.
  gboolean handle(UMockdevIoctlClient* client) {
    std::function<void(M2NanoSimulator&)> fire;
    {
      std::lock_guard lock(mutex);
      advance();
      const unsigned long request = umockdev_ioctl_client_get_request(client);
      UMockdevIoctlData* arg = umockdev_ioctl_client_get_arg(client);
      const size_t size = _IOC_SIZE(request);
      GError* error = nullptr;
      const auto resolve = [&](UMockdevIoctlData* data, size_t offset, size_t length) -> UMockdevIoctlData* {
        UMockdevIoctlData* child = umockdev_ioctl_data_resolve(data, offset, length, &error);
        if (error) g_clear_error(&error);
        return child;
      };
      const bool reap = request == USBDEVFS_REAPURB || request == USBDEVFS_REAPURBNDELAY;
      if (unplugged) {
        // As the kernel does when a device goes: its URBs in flight end with
        // ESHUTDOWN and can still be reaped (libusb ends their transfers
        // with "no device"); every other request fails with ENODEV.
        for (Urb& u : reads) u.fields()->status = -ESHUTDOWN, done.push_back(u);
        reads.clear();
        if (!reap || done.empty()) {
          complete(client, -1, ENODEV);
          return TRUE;
        }
      }
      switch (request) {
        case USBDEVFS_GET_CAPABILITIES: {
          UMockdevIoctlData* data = resolve(arg, 0, size);
          if (!data) return complete(client, -1, EFAULT), TRUE;
          const uint32_t capabilities = USBDEVFS_CAP_BULK_CONTINUATION | USBDEVFS_CAP_NO_PACKET_SIZE_LIM |
                                        USBDEVFS_CAP_REAP_AFTER_DISCONNECT | USBDEVFS_CAP_ZERO_PACKET;
          std::memcpy(data->data, &capabilities, sizeof capabilities);
          complete(client, 0, 0);
          g_object_unref(data);
          return TRUE;
        }
        case USBDEVFS_SETCONFIGURATION:
        case USBDEVFS_CLAIMINTERFACE:
        case USBDEVFS_RELEASEINTERFACE:
        case USBDEVFS_CLEAR_HALT:
        case USBDEVFS_RESET:
        case USBDEVFS_RESETEP:
          complete(client, 0, 0);
          return TRUE;
        case USBDEVFS_GETDRIVER:
        case USBDEVFS_IOCTL:  // no kernel driver holds the interface
          complete(client, -1, ENODATA);
          return TRUE;
        case USBDEVFS_SUBMITURB: {
          Urb u;
          u.urb = resolve(arg, 0, sizeof(usbdevfs_urb));
          if (!u.urb) return complete(client, -1, EFAULT), TRUE;
          const int length = u.fields()->buffer_length;
          if (length > 0) u.buffer = resolve(u.urb, offsetof(usbdevfs_urb, buffer), static_cast<size_t>(length));
          if (length > 0 && !u.buffer) return release(u), complete(client, -1, EFAULT), TRUE;
          if (u.fields()->type == kUrbBulk && (u.fields()->endpoint & 0x80)) {
            reads.push_back(u);  // answered when a reply is there (never, when muted)
          } else {
            transfer(u);
            done.push_back(u);
          }
          answerReads();
          complete(client, 0, 0);
          if (fault && counts.packetsAccepted >= faultAt) fire = std::exchange(fault, {});
          break;
        }
        case USBDEVFS_REAPURB:
        case USBDEVFS_REAPURBNDELAY: {
          if (!unplugged) answerReads();
          if (done.empty()) {
            complete(client, -1, EAGAIN);
            return TRUE;
          }
          UMockdevIoctlData* slot = resolve(arg, 0, size);
          if (!slot) return complete(client, -1, EFAULT), TRUE;
          Urb u = done.front();
          done.pop_front();
          umockdev_ioctl_data_set_ptr(slot, 0, u.urb);
          complete(client, 0, 0);
          g_object_unref(slot);
          release(u);
          return TRUE;
        }
        case USBDEVFS_DISCARDURB: {
          // The argument is the URB's address in the driver's memory.
          unsigned long address = 0;
          std::memcpy(&address, arg->data, std::min<size_t>(sizeof address, static_cast<size_t>(arg->data_len)));
          const auto it =
              std::find_if(reads.begin(), reads.end(), [&](const Urb& u) { return u.urb->client_addr == address; });
          if (it == reads.end()) return complete(client, -1, EINVAL), TRUE;
          Urb u = *it;
          reads.erase(it);
          u.fields()->status = -ENOENT;
          u.fields()->actual_length = 0;
          done.push_back(u);
          complete(client, 0, 0);
          return TRUE;
        }
        default:
          complete(client, -1, ENOTTY);
          return TRUE;
      }
    }
    if (fire) fire(*owner);
    return TRUE;
  }
};

namespace {

gboolean onIoctl(UMockdevIoctlBase*, UMockdevIoctlClient* client, gpointer state) {
  return static_cast<M2NanoSimulator::State*>(state)->handle(client);
}

}  // namespace

bool umockdevPreloaded() {
  std::ifstream maps("/proc/self/maps");
  std::string line;
  while (std::getline(maps, line)) {
    if (line.find("libumockdev-preload") != std::string::npos) return true;
  }
  return false;
}

void runUnderUmockdev(char** argv) {
  if (umockdevPreloaded()) {
    ::unsetenv("ROTAFAB_UMOCKDEV_RESTARTED");
    return;
  }
  // Where Debian's libumockdev0 puts it (pkg-config's libdir at build time).
  const std::string library = ROTAFAB_UMOCKDEV_PRELOAD;
  if (std::getenv("ROTAFAB_UMOCKDEV_RESTARTED") || ::access(library.c_str(), R_OK) != 0) {
    throw std::runtime_error(
        fmt::format("umockdev's preload library {} is not there or did not load (is Debian's "
                    "libumockdev0 installed?)",
                    library));
  }
  ::setenv("ROTAFAB_UMOCKDEV_RESTARTED", "1", 1);
  // After what is preloaded already (a sanitizer's runtime must come first).
  const char* preload = std::getenv("LD_PRELOAD");
  std::string libraries = preload && *preload ? std::string(preload) + ":" : std::string();
  libraries += library;
  ::setenv("LD_PRELOAD", libraries.c_str(), 1);
  // In a sanitizer build the preload comes before the sanitizer's runtime, which it would refuse.
  std::string asan = std::getenv("ASAN_OPTIONS") ? std::getenv("ASAN_OPTIONS") : "";
  asan.append(asan.empty() ? "" : ":").append("verify_asan_link_order=0");
  ::setenv("ASAN_OPTIONS", asan.c_str(), 1);
  ::execv("/proc/self/exe", argv);
  throw std::runtime_error(fmt::format("cannot run again under umockdev: {}", std::strerror(errno)));
}

M2NanoSimulator::M2NanoSimulator(M2NanoSimulatorOptions options) : state_(std::make_unique<State>(options)) {
  if (!umockdevPreloaded()) {
    throw std::runtime_error("sim:m2nano needs umockdev's preload library in this process (runUnderUmockdev)");
  }
  state_->owner = this;
  state_->testbed = umockdev_testbed_new();
  GError* error = nullptr;
  if (!umockdev_testbed_add_from_string(state_->testbed, kDevice, &error)) {
    const std::string message = error ? error->message : "unknown error";
    g_clear_error(&error);
    g_object_unref(state_->testbed);
    throw std::runtime_error("sim:m2nano: umockdev refused the device: " + message);
  }
  state_->handler = umockdev_ioctl_base_new();
  g_signal_connect(state_->handler, "handle-ioctl", G_CALLBACK(onIoctl), state_.get());
  if (!umockdev_testbed_attach_ioctl(state_->testbed, kDeviceNode, state_->handler, &error)) {
    const std::string message = error ? error->message : "unknown error";
    g_clear_error(&error);
    g_object_unref(state_->handler);
    g_object_unref(state_->testbed);
    throw std::runtime_error("sim:m2nano: umockdev cannot serve the device: " + message);
  }
}

M2NanoSimulator::~M2NanoSimulator() {
  // No request reaches the state once it is gone (a driver may still hold the device open).
  g_signal_handlers_disconnect_by_data(state_->handler, state_.get());
  umockdev_testbed_detach_ioctl(state_->testbed, kDeviceNode, nullptr);
  g_object_unref(state_->testbed);
  g_object_unref(state_->handler);
  std::lock_guard lock(state_->mutex);
  for (Urb& u : state_->done) release(u);
  for (Urb& u : state_->reads) release(u);
}

UsbMatch M2NanoSimulator::match() const { return UsbMatch{0x1a86, 0x5512, 1, 4}; }

M2NanoSimulatorRecord M2NanoSimulator::record() const {
  std::lock_guard lock(state_->mutex);
  state_->advance();
  M2NanoSimulatorRecord r = state_->counts;
  const LhymicroBoard& board = state_->board;
  r.laser = board.laser(), r.busy = board.busy();
  r.mode = board.mode();
  r.x = board.x(), r.y = board.y();
  r.trace = board.trace();
  r.violations = board.violations();
  return r;
}

void M2NanoSimulator::unplug() {
  std::lock_guard lock(state_->mutex);
  state_->unplugged = true;
}

void M2NanoSimulator::mute(bool silent) {
  std::lock_guard lock(state_->mutex);
  state_->muted = silent;
}

void M2NanoSimulator::corruptPackets(size_t count) {
  std::lock_guard lock(state_->mutex);
  state_->corrupt = count;
}

void M2NanoSimulator::sendGarbage() {
  std::lock_guard lock(state_->mutex);
  state_->garbage = true;
}

void M2NanoSimulator::powerFault(bool on) {
  std::lock_guard lock(state_->mutex);
  state_->power = on;
}

void M2NanoSimulator::afterPackets(size_t packets, std::function<void(M2NanoSimulator&)> fault) {
  std::lock_guard lock(state_->mutex);
  state_->faultAt = packets;
  state_->fault = std::move(fault);
}

}  // namespace rotafab::devices::sim
