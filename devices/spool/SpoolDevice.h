#pragma once
// The spool "driver" (`spool:DIR[?printer=NAME]`): for cutters
// driven through a print driver, as the dissertation's workshop cutter was.
// Each sheet's toolpath becomes an EPS file in DIR, drawn in the machine's
// colours (the print driver maps colours to power, speed and passes, fig. 65),
// and with a printer name it is handed to `lp`. Nothing here lights a laser:
// the print driver does, after this program is done.

#include <filesystem>
#include <map>
#include <string>

#include "devices/Device.h"
#include "devices/DriverEntry.h"

namespace rotafab::devices::spool {

// The sheet a toolpath draws: each stroke once (the print driver repeats the
// passes), in cutting order, closed strokes closed, in the machine's colours.
jobs::SheetDrawing drawingOf(const jobs::Toolpath& toolpath, const std::map<jobs::Operation, jobs::Rgb>& colours);

class SpoolDevice : public Device {
 public:
  // `colours`: the machine profile's colour for each operation.
  SpoolDevice(std::filesystem::path folder, std::string printer, std::map<jobs::Operation, jobs::Rgb> colours);
  std::string connect() override;
  void home() override {}
  void frame(const jobs::Toolpath&, const core::Cancellation&) override {}
  void run(const jobs::Toolpath& toolpath, const std::function<void(const Progress&)>& progress,
           const core::Cancellation& cancel) override;
  void pause() override {}
  void resume() override {}
  DeviceStatus status() override { return {"Idle", 0, 0}; }
  bool stopSafely() noexcept override { return true; }  // a spool lights no laser
  void disconnect() override {}
  // Each sheet's EPS, one after another.
  [[nodiscard]] std::string program(const std::vector<jobs::Toolpath>& toolpaths) const override;
  [[nodiscard]] std::string describeProgram(const std::vector<jobs::Toolpath>& toolpaths) const override;

 private:
  std::filesystem::path folder_;
  std::string printer_;
  std::map<jobs::Operation, jobs::Rgb> colours_;
};

// The registry's entry (DriverEntry.h): spool:DIR[?printer=NAME].
const DriverEntry& entry();

}  // namespace rotafab::devices::spool
