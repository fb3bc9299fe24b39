#include <gtest/gtest.h>

#include <cstdlib>

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  // The tests see none of the user's settings or profiles (~/.config/rotafab:
  // `units: mm` there would change every length they read); a test that
  // wants some gives its own XDG_CONFIG_HOME.
  ::setenv("XDG_CONFIG_HOME", "/nonexistent/rotafab-tests-config", 1);
  return RUN_ALL_TESTS();
}
