#pragma once
// The helper side of a RemoteDevice (RemoteDevice.h): serves one device's
// calls, as RemoteProtocol.h has them, from its input to its output until
// the input ends. While a run goes on, pause, resume and cancel are taken at
// once; when the input ends (the program that asked is gone, even killed),
// a run is cancelled, so the driver leaves the laser off.

#include "devices/Device.h"

namespace rotafab::devices::remote {

// Returns when the input has ended and the device is disconnected.
void serveDevice(Device& device, int input, int output);

// The same, for a device that could not be made: every request is answered with `error`.
void serveError(const std::string& error, int input, int output);

}  // namespace rotafab::devices::remote
