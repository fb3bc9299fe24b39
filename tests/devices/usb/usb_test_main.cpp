// The USB tests run the real libusb code against devices umockdev simulates,
// which needs its preloaded library: the program starts again with it first.

#include <gtest/gtest.h>

#include <cstdio>
#include <stdexcept>

#include "devices/sim/M2NanoSimulator.h"

int main(int argc, char** argv) {
  try {
    rotafab::devices::sim::runUnderUmockdev(argv);
  } catch (const std::runtime_error& error) {
    std::fprintf(stderr, "%s\n", error.what());
    return 1;
  }
  ::testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
