#pragma once
// Shared by the config tests: load YAML text that must be refused and return
// the whole message (a test failure if it loads).
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "config/config.hpp"

namespace canmotion::config::test {

/// The diagnostics of the ConfigError of loading `yaml` as file `name`; empty
/// (and a test failure) when the text loads.
inline std::vector<Diagnostic> diagnostics_of(const std::string& yaml, const std::string& name = "test.yaml") {
  try {
    (void)load_string(yaml, name);
  } catch (const ConfigError& e) {
    return e.diagnostics();
  }
  ADD_FAILURE() << "configuration was accepted:\n" << yaml;
  return {};
}

/// The ConfigError message (every error, one per line) of loading `yaml` as
/// file `name`; empty (and a test failure) when the text loads.
inline std::string errors_of(const std::string& yaml, const std::string& name = "test.yaml") {
  const std::vector<Diagnostic> d = diagnostics_of(yaml, name);
  return d.empty() ? std::string() : ConfigError(d).what();
}

}  // namespace canmotion::config::test
