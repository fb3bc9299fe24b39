#pragma once
// Ruida controllers on the network: a memory read of the card ID sent to
// an address (the broadcast address finds every controller on the local
// network), and the controllers that answer within a moment.

#include <cstdint>
#include <string>
#include <vector>

#include "devices/ruida/RuidaCodec.h"
#include "devices/transport/SerialLink.h"

namespace rotafab::devices::ruida {

struct FoundController {
  std::string address;  // "192.168.1.100"
  int64_t card = 0;     // its card ID, 0 when it only acknowledged
};

// Never throws: a network that cannot be reached, or a reply port taken,
// finds nothing.
std::vector<FoundController> probeControllers(const std::string& target, uint16_t port, uint16_t localPort, Millis wait,
                                              uint8_t magic = kDefaultMagic);

}  // namespace rotafab::devices::ruida
