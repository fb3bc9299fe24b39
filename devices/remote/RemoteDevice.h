#pragma once
// A device driven in a helper process, through the line protocol of
// RemoteProtocol.h, with the Device interface of any other: for sim:m2nano,
// whose simulated board needs umockdev's preloaded library in the process
// that runs libusb (which the program that asks for the device, a command
// or the daemon, must not need). The helper is started at connect(), its
// standard input and output a socket to this side; its signals blocked as
// this process's are (Ctrl-C reaches it only as a cancel from here). If
// this side goes, even killed, the helper's input ends and it cancels the
// run, so the driver in it leaves the laser off.

#include <sys/types.h>

#include <memory>
#include <string>
#include <vector>

#include "devices/Device.h"
#include "devices/remote/LinePipe.h"
#include "devices/remote/RemoteProtocol.h"

namespace rotafab::devices::remote {

struct RemoteTimeouts {
  std::chrono::milliseconds request{30000};  // for the reply to a request
  std::chrono::milliseconds home{180000};    // to home or frame
  std::chrono::milliseconds stop{60000};     // after a cancel, for the run to end
  // With no word at all from the helper this long (it says it is alive every
  // second while it serves a request), it is taken for hung.
  std::chrono::milliseconds silence{10000};
  // After its input ends, for the helper to end (it stops a run safely
  // first, which can take a board's home); then it is killed.
  std::chrono::milliseconds exit{60000};
};

class RemoteDevice : public Device {
 public:
  // `argv`: the helper program and its arguments.
  explicit RemoteDevice(std::vector<std::string> argv, RemoteTimeouts timeouts = {});
  ~RemoteDevice() override;  // ends the helper: its input closed, then killed if it lingers

  std::string connect() override;
  void home() override;
  void frame(const jobs::Toolpath& toolpath, const core::Cancellation& cancel) override;
  void run(const jobs::Toolpath& toolpath, const std::function<void(const Progress&)>& progress,
           const core::Cancellation& cancel) override;
  void pause() override;
  void resume() override;
  DeviceStatus status() override;
  bool stopSafely() noexcept override;
  void disconnect() override;

 private:
  void start();
  // Ends the helper: its input closed (it stops a run safely and goes), then
  // killed if it lingers past the exit timeout. Never throws.
  void stop() noexcept;
  // Sends a request and waits for its reply (progress goes to `progress`);
  // a fault the helper reports is thrown as the DeviceFault it was. Anything
  // else that goes wrong here (no answer, a garbled one, a progress callback
  // that throws) ends the helper first, so that a job in it stops, and is
  // thrown as a DeviceFault whose laser-off is not confirmed.
  nlohmann::json call(nlohmann::json request, std::chrono::milliseconds timeout,
                      const std::function<void(const Progress&)>& progress = {},
                      const core::Cancellation* cancel = nullptr);

  std::vector<std::string> argv_;
  RemoteTimeouts timeouts_;
  pid_t child_ = -1;
  std::unique_ptr<LinePipe> pipe_;
  long nextId_ = 0;               // each request's, echoed by its replies
  bool heardFromHelper_ = false;  // since it started
};

}  // namespace rotafab::devices::remote
