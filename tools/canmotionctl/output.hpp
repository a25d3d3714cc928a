#pragma once
// canmotionctl: how the answers to STATUS and STATS are printed.
#include <map>
#include <string>
#include <vector>

namespace canmotionctl {

/// key=value fields of a STATUS line (values may be "quoted").
std::map<std::string, std::string> fields(const std::string& line);
/// STATUS's data lines as a table, long bit lists and failures under it, then (footer).
void print_status_table(const std::vector<std::string>& lines, const std::string& footer);
/// STATS's key=value lines aligned; *_ns values in microseconds.
void print_stats(const std::vector<std::string>& lines);

}  // namespace canmotionctl
