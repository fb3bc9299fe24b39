// The registry of drivers (DriverEntry.h): each driver's folder gives its
// entry; this is only the list.

#include <fmt/format.h>

#include "devices/DriverEntry.h"
#include "devices/UriParts.h"
#include "devices/grbl/GrblDriver.h"
#include "devices/m2nano/M2NanoDriver.h"
#include "devices/ruida/RuidaDriver.h"
#include "devices/sim/SimEntries.h"
#include "devices/spool/SpoolDevice.h"

namespace rotafab::devices {

const std::vector<const DriverEntry*>& drivers() {
  static const std::vector<const DriverEntry*> all{&grbl::entry(),    &m2nano::entry(),  &ruida::entry(),
                                                   &spool::entry(),   &sim::grblEntry(), &sim::m2nanoEntry(),
                                                   &sim::ruidaEntry()};
  return all;
}

ParsedUri parseDeviceUri(const std::string& uri) {
  for (const DriverEntry* driver : drivers()) {
    if (driver->takes(uri)) return {driver, driver->parse(uri)};
  }
  if (uri.starts_with("sim:")) {
    std::string simulators;
    for (const DriverEntry* driver : drivers()) {
      if (driver->simulated()) simulators += fmt::format("{}{}", simulators.empty() ? "" : " and ", driver->scheme());
    }
    throw uriError(uri, "the simulators are " + simulators);
  }
  throw uriError(uri, "not a device URI this program knows");
}

std::vector<const DriverEntry*> driversForUsb(int vendor, int product) {
  std::vector<const DriverEntry*> fitting;
  for (const DriverEntry* driver : drivers()) {
    for (const UsbId& id : driver->usbIds()) {
      if (id.vendor == vendor && (!id.product || *id.product == product)) {
        fitting.push_back(driver);
        break;
      }
    }
  }
  return fitting;
}

}  // namespace rotafab::devices
