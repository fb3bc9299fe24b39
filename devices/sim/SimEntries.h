#pragma once
// The simulated devices' entries in the registry (DriverEntry.h), each as
// the driver of the machine it simulates: sim:grbl[?speed=N] (a GRBL on a
// pseudo-terminal, in this process) and sim:m2nano[?speed=N] (an M2 Nano on
// USB through umockdev, in a helper program of its own,
// rotafab-sim-m2nano, beside this one: the umockdev simulator lives there
// and in the tests, nowhere else) and sim:ruida[?speed=N] (a Ruida
// controller on loopback UDP, in this process). N: simulated seconds per
// real second.

#include "devices/DriverEntry.h"

namespace rotafab::devices::sim {

const DriverEntry& grblEntry();
const DriverEntry& m2nanoEntry();
const DriverEntry& ruidaEntry();

// The helper program that runs the simulated M2 Nano and its driver.
constexpr const char* kM2NanoHelper = "rotafab-sim-m2nano";

}  // namespace rotafab::devices::sim
