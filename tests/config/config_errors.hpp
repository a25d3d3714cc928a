#pragma once
// Shared by the config tests: load YAML text that must be refused and return
// the whole message (a test failure if it loads).
#include <gtest/gtest.h>

#include <string>

#include "config/config.hpp"

namespace canmotion::config::test {

/// The ConfigError message of loading `yaml` as file `name`; empty (and a
/// test failure) when the text loads.
inline std::string errors_of(const std::string& yaml, const std::string& name = "test.yaml") {
  try {
    (void)load_string(yaml, name);
  } catch (const ConfigError& e) {
    return e.what();
  }
  ADD_FAILURE() << "configuration was accepted:\n" << yaml;
  return {};
}

}  // namespace canmotion::config::test
