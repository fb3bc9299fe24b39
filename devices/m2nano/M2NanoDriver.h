#pragma once
// The Lihuiyu M2 Nano board (K40 lasers) over USB. The board sits
// behind a CH341 bridge in parallel mode (1a86:5512): the driver initialises
// it with one control transfer, sends each 30-byte LHYMICRO-GL packet
// (Lhymicro.h) as a 34-byte bulk transfer, and after each one asks for the
// status (0xA0 out, six bytes in, the second one the status): 206 OK, the
// packet is taken; 238 busy, ask again; 207 the packet arrived corrupted,
// send it again; 236 the job has finished; 239 a power fault. Learnt from
// MeerK40t, K40 Whisperer and LibLaserCut (none of their code is used).
// On any fault or cancel the driver sends "I", which drops what the board
// has queued and leaves compact mode, so the laser is off; that is
// confirmed when the board has homed after it. A pause holds the job at the
// end of a stroke, the laser off, and a resume sends the rest.

#include <atomic>
#include <functional>
#include <memory>

#include "devices/Device.h"
#include "devices/DriverEntry.h"
#include "devices/m2nano/Lhymicro.h"
#include "devices/transport/UsbLink.h"

namespace rotafab::devices::m2nano {

struct M2NanoTimeouts {
  Millis transfer{1500};   // any one USB transfer
  Millis ready{5000};      // for the board to report OK after connecting or an abort
  Millis busy{60000};      // for a busy board to take the next packet (its queue drains as it cuts; more for slow jobs)
  Millis stop{30000};      // after a fault: for the board to take "I" and home
  Millis poll{20};         // between status requests while the board is busy
  int crcResends = 50;     // a packet rejected this many times in a row is a fault
  double finishSlack = 3;  // wait this many times the estimated time (plus a minute) for the job to finish
};

class M2NanoDriver : public Device {
 public:
  M2NanoDriver(std::function<std::unique_ptr<UsbLink>()> open, M2NanoTimeouts timeouts = {});
  std::string connect() override;
  void home() override;
  void frame(const jobs::Toolpath& toolpath, const core::Cancellation& cancel) override;
  void run(const jobs::Toolpath& toolpath, const std::function<void(const Progress&)>& progress,
           const core::Cancellation& cancel) override;
  // A hold is wanted from pause() until resume(); run() holds at the next
  // stroke's end (one the board has not been sent yet: a pause in the last
  // few packets of a job comes too late, and the job ends).
  void pause() override { holdWanted_ = true; }
  void resume() override { holdWanted_ = false; }
  DeviceStatus status() override;
  bool stopSafely() noexcept override;
  void disconnect() override;

  // The M2's limits (a profile's 100% speed is 100 mm/s), its LHYMICRO-GL
  // as an .egv file.
  [[nodiscard]] jobs::MotionLimits motionLimits() const override { return m2nano::motionLimits(); }
  [[nodiscard]] std::string program(const std::vector<jobs::Toolpath>& toolpaths) const override;
  [[nodiscard]] std::string describeProgram(const std::vector<jobs::Toolpath>& toolpaths) const override;

  // Packets the board asked for again (CRC errors), since connect().
  [[nodiscard]] size_t resends() const { return resends_; }

 private:
  int readStatus();
  // Sends one packet until the board takes it (status OK), by `deadline` if one is given.
  void send(const Packet& packet, const core::Cancellation* cancel,
            std::chrono::steady_clock::time_point deadline = std::chrono::steady_clock::time_point::max());
  void sendLines(const std::vector<std::string>& lines, const core::Cancellation* cancel);
  // Polls until the board reports the job finished (236).
  void waitFinished(Millis limit, const core::Cancellation* cancel);
  // "I", then a home; whether the board confirmed both. Never throws.

  std::function<std::unique_ptr<UsbLink>()> open_;
  M2NanoTimeouts timeouts_;
  std::unique_ptr<UsbLink> link_;
  std::atomic<bool> holdWanted_{false};
  bool paused_ = false;           // held at the end of a stroke
  bool finishedSeen_ = false;     // the board said "finished" after the last packet sent
  Millis busy_ = timeouts_.busy;  // this job's limit for a busy board
  size_t resends_ = 0;
};

// The registry's entry (DriverEntry.h): m2nano://usb/VENDOR:PRODUCT[?bus=B&address=A]; the CH341 in parallel mode.
const DriverEntry& entry();

}  // namespace rotafab::devices::m2nano
