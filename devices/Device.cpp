#include "devices/Device.h"

namespace rotafab::devices {

std::string_view faultName(FaultKind kind) {
  switch (kind) {
    case FaultKind::Timeout:
      return "timeout";
    case FaultKind::Disconnected:
      return "disconnected";
    case FaultKind::Alarm:
      return "alarm";
    case FaultKind::Error:
      return "error";
    case FaultKind::Refused:
      return "refused";
    case FaultKind::Protocol:
      return "protocol";
    case FaultKind::Cancelled:
      return "cancelled";
    case FaultKind::Stalled:
      return "stalled";
  }
  return "fault";
}

std::string laserStateAfter(const DeviceFault& fault) {
  if (fault.nothingSent) return "nothing that lights the laser was sent";
  if (fault.laserOffConfirmed) return "the controller confirmed the laser off";
  return "the controller did not confirm the laser off: switch it off at the machine";
}

void stopAndRethrow(const std::function<bool()>& stopSafely) {
  try {
    throw;
  } catch (DeviceFault& fault) {
    fault.laserOffConfirmed = stopSafely();
    throw;
  } catch (...) {
    stopSafely();
    throw;
  }
}

}  // namespace rotafab::devices
