#pragma once
// A CO2 laser on a Ruida controller (RDC6442, RDC6445, 634XG), over its
// network port or its USB port (RuidaChannel.h). A sheet is sent as the job
// RDWorks sends (RuidaJob.h): the controller stores it as it comes and cuts
// it; the driver then reads the controller's status until the job has
// ended. Pause, resume and stop are the controller's own commands (D8 02,
// D8 03, D8 01), each of which leaves the laser off; on any fault or cancel
// the driver sends the stop, and the laser off is confirmed when the
// controller then reports no job running. The frame is a job of moves
// alone, with nothing in it that lights the laser.

#include <atomic>
#include <functional>
#include <memory>

#include "devices/Device.h"
#include "devices/DriverEntry.h"
#include "devices/ruida/RuidaChannel.h"
#include "devices/ruida/RuidaJob.h"

namespace rotafab::devices::ruida {

class RuidaDriver : public Device {
 public:
  // `motion`: the machine profile's (the controller's own settings are on its panel).
  RuidaDriver(std::function<std::unique_ptr<RuidaChannel>()> open, uint8_t magic, jobs::MotionLimits motion,
              RuidaTimeouts timeouts = {}, double timeScale = 1);
  std::string connect() override;
  void home() override;
  void frame(const jobs::Toolpath& toolpath, const core::Cancellation& cancel) override;
  void run(const jobs::Toolpath& toolpath, const std::function<void(const Progress&)>& progress,
           const core::Cancellation& cancel) override;
  // Asked from another thread: run() sends the controller's pause (or
  // resume) between its packets and status reads.
  void pause() override { holdWanted_ = true; }
  void resume() override { holdWanted_ = false; }
  DeviceStatus status() override;
  bool stopSafely() noexcept override;
  void disconnect() override;
  [[nodiscard]] double timeScale() const override { return timeScale_; }
  [[nodiscard]] jobs::MotionLimits motionLimits() const override { return motion_; }

  // The job as RDWorks saves it (.rd): swizzled with the controller's magic.
  [[nodiscard]] std::string program(const std::vector<jobs::Toolpath>& toolpaths) const override;
  [[nodiscard]] std::string describeProgram(const std::vector<jobs::Toolpath>& toolpaths) const override;

  [[nodiscard]] size_t resends() const { return channel_ ? channel_->resends() : 0; }
  // Packets sent (status reads included), since connected.
  [[nodiscard]] size_t packets() const { return channel_ ? channel_->packets() : 0; }

 private:
  // Sends a job (frame or sheet) packet by packet, then reads the status
  // until the controller has run it; `tell(bytes sent, time it has run
  // since the last, held times not counted)` after each packet and status read.
  // A job that must run (a sheet) and is never seen to is a fault; a frame's is not.
  void runJob(const Bytes& stream, double machineSeconds, bool mustRun, const std::function<void(size_t, Millis)>& tell,
              const core::Cancellation& cancel);
  void followHold(bool& held);
  [[nodiscard]] std::string where() const;

  std::function<std::unique_ptr<RuidaChannel>()> open_;
  uint8_t magic_;
  jobs::MotionLimits motion_;
  RuidaTimeouts timeouts_;
  double timeScale_;
  std::unique_ptr<RuidaChannel> channel_;
  double bedHeight_ = 0;  // inches, as the controller reports its bed
  std::atomic<bool> holdWanted_{false};
};

// The registry's entries (DriverEntry.h): ruida://HOST[:PORT][?bind=PORT&magic=0xNN]
// and ruida+serial:///dev/ttyUSB0[?baud=N&magic=0xNN].
const DriverEntry& entry();

}  // namespace rotafab::devices::ruida
