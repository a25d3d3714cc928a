#pragma once
// Shared by the EDS tests: a valid EDS around a few object sections, the
// line of a text in it, and the errors of a file that must be refused.
#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include <fmt/format.h>

#include "fieldbus/eds/dcf.hpp"
#include "fieldbus/eds/eds.hpp"

namespace canmotion::eds::test {

/// A valid EDS: [DeviceInfo] (2 RPDOs, 2 TPDOs), [MandatoryObjects] with
/// 0x1000 (and its section), then `body`; `optional` and `manufacturer`
/// are the other lists (each given only when not empty).
inline std::string eds_text(std::string_view body, const std::vector<std::uint16_t>& manufacturer = {},
                            const std::vector<std::uint16_t>& optional = {}) {
  std::string s =
      "[FileInfo]\n"
      "FileName=test.eds\n"
      "EDSVersion=4.0\n"
      "\n"
      "[DeviceInfo]\n"
      "VendorName=test\n"
      "VendorNumber=0x12345678\n"
      "ProductName=test drive\n"
      "ProductNumber=0x402\n"
      "RevisionNumber=0x00020001\n"
      "BaudRate_500=1\n"
      "BaudRate_1000=1\n"
      "Granularity=8\n"
      "NrOfRXPDO=2\n"
      "NrOfTXPDO=2\n"
      "\n"
      "[MandatoryObjects]\n"
      "SupportedObjects=1\n"
      "1=0x1000\n"
      "\n";
  const auto list = [&](const char* name, const std::vector<std::uint16_t>& l) {
    if (l.empty()) return;
    s += fmt::format("[{}]\nSupportedObjects={}\n", name, l.size());
    for (std::size_t i = 0; i < l.size(); ++i) s += fmt::format("{}=0x{:04X}\n", i + 1, l[i]);
    s += "\n";
  };
  list("OptionalObjects", optional);
  list("ManufacturerObjects", manufacturer);
  s +=
      "[1000]\n"
      "ParameterName=Device type\n"
      "ObjectType=0x7\n"
      "DataType=0x0007\n"
      "AccessType=ro\n"
      "DefaultValue=0x00020192\n"
      "PDOMapping=0\n"
      "\n";
  s += body;
  return s;
}

/// 1-based line of the first occurrence of `what` in `text` (a test
/// failure and 0 when absent); `nth` > 1 for later occurrences.
inline int line_of(std::string_view text, std::string_view what, int nth = 1) {
  std::size_t pos = 0;
  for (int i = 0; i < nth; ++i) {
    pos = text.find(what, i == 0 ? 0 : pos + 1);
    if (pos == std::string_view::npos) {
      ADD_FAILURE() << "'" << what << "' not in the text";
      return 0;
    }
  }
  int line = 1;
  for (std::size_t i = 0; i < pos; ++i)
    if (text[i] == '\n') ++line;
  return line;
}

/// The errors of parsing `text` as `file` (a test failure if it parses).
inline std::vector<Diagnostic> errors_of(const std::string& text, const std::string& file = "bad.eds") {
  try {
    (void)parse(text, file);
  } catch (const ParseError& e) {
    return e.errors();
  }
  ADD_FAILURE() << "the file was accepted:\n" << text;
  return {};
}

/// The warnings of reading `text` as `file` (a test failure if it is refused).
inline std::vector<Diagnostic> warnings_of(const std::string& text, const std::string& file = "bad.eds") {
  try {
    return parse(text, file).warnings;
  } catch (const ParseError& e) {
    ADD_FAILURE() << "the file was refused:\n" << e.what();
  }
  return {};
}

/// The warnings of `text` as "file:line: message", one per line.
inline std::string warning_text(const std::string& text, const std::string& file = "bad.eds") {
  std::string s;
  for (const Diagnostic& d : warnings_of(text, file)) s += (s.empty() ? "" : "\n") + d.to_string();
  return s;
}

/// ParseError::what() of `text`: every error as "file:line: message".
inline std::string error_text(const std::string& text, const std::string& file = "bad.eds") {
  const auto e = errors_of(text, file);
  return e.empty() ? std::string() : ParseError(e).what();
}

/// A master's boot writes to node 5 (500 kbit/s, "X"): a VAR, a record
/// without its sub-index 0, the PDO procedure writing 0x1400:1 and 0x1600:0
/// twice, a manufacturer object unknown to the object table.
inline DcfSpec dcf_spec() {
  DcfSpec s;
  s.node_id = 5;
  s.baudrate_kbit = 500;
  s.node_name = "X";
  s.writes = {{0x6060, 0, 1, 8, ""},
              {0x60C2, 1, 1, 1, "controller.period_ms"},
              {0x60C2, 2, 1, 0xFD, "controller.period_ms"},
              {0x1400, 1, 4, 0x80000205u, "axes[0].drive.pdo"},
              {0x1600, 0, 1, 0, "axes[0].drive.pdo"},
              {0x1600, 1, 4, 0x60400010u, "axes[0].drive.pdo"},
              {0x1600, 0, 1, 1, "axes[0].drive.pdo"},
              {0x1400, 1, 4, 0x205u, "axes[0].drive.pdo"},
              {0x2100, 3, 2, 0x1234, "axes[0].drive.sdo_writes[0] (line 9)"}};
  return s;
}

}  // namespace canmotion::eds::test
