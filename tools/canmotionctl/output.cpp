// canmotionctl: printing STATUS and STATS (see output.hpp).
#include "tools/canmotionctl/output.hpp"

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <utility>

#include <fmt/format.h>

namespace canmotionctl {

std::map<std::string, std::string> fields(const std::string& line) {
  std::map<std::string, std::string> m;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && line[i] == ' ') ++i;
    const std::size_t eq = line.find('=', i);
    if (eq == std::string::npos) break;
    const std::string key = line.substr(i, eq - i);
    std::size_t j = eq + 1;
    std::string value;
    if (j < line.size() && line[j] == '"') {
      const std::size_t end = line.find('"', j + 1);
      value = line.substr(j + 1, end == std::string::npos ? std::string::npos : end - j - 1);
      j = end == std::string::npos ? line.size() : end + 1;
    } else {
      const std::size_t end = line.find(' ', j);
      value = line.substr(j, end == std::string::npos ? std::string::npos : end - j);
      j = end == std::string::npos ? line.size() : end;
    }
    m[key] = value;
    i = j;
  }
  return m;
}

void print_status_table(const std::vector<std::string>& lines, const std::string& footer) {
  const std::vector<std::pair<const char*, const char*>> cols = {
      {"AXIS", "axis"},       {"TYPE", "type"},       {"NODE", "node"},       {"STATE", "state"},
      {"DRIVE", "drive"},     {"CMD_POS", "cmd_pos"}, {"ACT_POS", "act_pos"}, {"CMD_VEL", "cmd_vel"},
      {"ACT_VEL", "act_vel"}, {"POS_ERR", "pos_err"}, {"EMCY", "last_emcy"},  {"MOTION", "motion_bits"},
  };
  std::vector<std::map<std::string, std::string>> rows;
  for (const auto& l : lines) rows.push_back(fields(l));
  std::vector<std::size_t> width;
  for (const auto& [head, key] : cols) {
    std::size_t w = std::strlen(head);
    for (auto& r : rows) w = std::max(w, r.count(key) ? r[key].size() : 1);
    width.push_back(w);
  }
  auto cell = [](const std::string& v, std::size_t w) { return fmt::format("{:<{}}  ", v, w); };
  std::string head;
  for (std::size_t c = 0; c < cols.size(); ++c) head += cell(cols[c].first, c + 1 == cols.size() ? 0 : width[c]);
  fmt::print("{}\n", head.substr(0, head.find_last_not_of(' ') + 1));
  for (auto& r : rows) {
    std::string l;
    for (std::size_t c = 0; c < cols.size(); ++c) {
      const std::string v = r.count(cols[c].second) ? r[cols[c].second] : "-";
      l += cell(v, c + 1 == cols.size() ? 0 : width[c]);
    }
    fmt::print("{}\n", l.substr(0, l.find_last_not_of(' ') + 1));
  }
  // Status and fault bits and failures: long, one line each under the table.
  for (auto& r : rows) {
    const std::string name = r["axis"];
    if (r.count("status_bits") && r["status_bits"] != "-") fmt::print("  {}: AxisStatus {}\n", name, r["status_bits"]);
    if (r.count("faults") && r["faults"] != "-") fmt::print("  {}: AxisFault {}\n", name, r["faults"]);
    if (r.count("failure")) fmt::print("  {}: drive failure: {}\n", name, r["failure"]);
  }
  if (!footer.empty()) fmt::print("({})\n", footer);
}

void print_stats(const std::vector<std::string>& lines) {
  for (const auto& l : lines) {
    const std::size_t eq = l.find('=');
    const std::string k = l.substr(0, eq), v = eq == std::string::npos ? "" : l.substr(eq + 1);
    if (k.size() > 3 && k.compare(k.size() - 3, 3, "_ns") == 0 && k != "period_ns")
      fmt::print("{:<26} {:>12.1f} us\n", k.substr(0, k.size() - 3), std::strtod(v.c_str(), nullptr) / 1e3);
    else
      fmt::print("{:<26} {:>12}\n", k, v);
  }
}

}  // namespace canmotionctl
