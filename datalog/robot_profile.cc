#include "datalog/robot_profile.h"

#include <stdexcept>

#include "datalog/log_error.h"

namespace hadynet::datalog {

namespace {

bool is_name(const std::string& s) {
  if (s.empty()) return false;
  for (char c : s) {
    if (!((c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_')) return false;
  }
  return true;
}

// Splits on `sep`; every item must be non-empty.
std::vector<std::string> split_on(const std::string& text, char sep, const char* what) {
  std::vector<std::string> out;
  std::size_t start = 0;
  while (true) {
    const std::size_t end = std::min(text.find(sep, start), text.size());
    std::string item = text.substr(start, end - start);
    if (item.empty()) {
      throw std::invalid_argument(std::string("empty ") + what + " in '" + text + "'");
    }
    out.push_back(std::move(item));
    if (end == text.size()) return out;
    start = end + 1;
  }
}

}  // namespace

std::vector<std::string> split_list(const std::string& text) {
  if (text.empty() || text == "none") return {};
  return split_on(text, ',', "item");
}

std::string join_list(const std::vector<std::string>& items) {
  std::string out;
  for (std::size_t i = 0; i < items.size(); ++i) out += (i ? "," : "") + items[i];
  return out;
}

std::vector<ContactSum> parse_contact_sums(const std::string& text) {
  std::vector<ContactSum> out;
  if (text.empty() || text == "none") return out;
  for (const std::string& item : split_on(text, ' ', "contact sum")) {
    const std::size_t eq = item.find('=');
    if (eq == std::string::npos) throw std::invalid_argument("contact sum '" + item + "' has no '='");
    ContactSum sum{item.substr(0, eq), {}};
    if (!is_name(sum.name)) {
      throw std::invalid_argument("contact sum name '" + sum.name + "' is not [a-z0-9_]+");
    }
    for (const auto& c : out) {
      if (c.name == sum.name) throw std::invalid_argument("contact sum '" + sum.name + "' given twice");
    }
    sum.channels = split_on(item.substr(eq + 1), '+', "channel");
    out.push_back(std::move(sum));
  }
  return out;
}

std::string contact_sums_text(const std::vector<ContactSum>& sums) {
  std::string out;
  for (std::size_t i = 0; i < sums.size(); ++i) {
    out += (i ? " " : "") + sums[i].name + "=";
    for (std::size_t j = 0; j < sums[i].channels.size(); ++j) out += (j ? "+" : "") + sums[i].channels[j];
  }
  return out;
}

void write_profile(const RobotProfile& p, LogMetadata& metadata) {
  const auto list = [&metadata](const char* key, const std::vector<std::string>& items) {
    if (!items.empty()) metadata.set(key, join_list(items));
  };
  list(kDeltaGroupsKey, p.delta_groups);
  list(kForceGroupsKey, p.force_groups);
  list(kAngleGroupsKey, p.angle_groups);
  list(kLengthGroupsKey, p.length_groups);
  list(kControlCommandsKey, p.control_commands);
  if (!p.board_group.empty()) metadata.set(kBoardGroupKey, p.board_group);
  if (!p.contact_sums.empty()) metadata.set(kContactSumsKey, contact_sums_text(p.contact_sums));
}

RobotProfile read_profile(const LogMetadata& metadata, const std::string& where) {
  RobotProfile p;
  const auto field = [&](const char* key, auto parse) {
    const auto value = metadata.get(key);
    if (!value) return decltype(parse(std::string()))();
    try {
      return parse(*value);
    } catch (const std::invalid_argument& e) {
      throw LogError(where, 0, 0, "", std::string("metadata '") + key + "': " + e.what());
    }
  };
  p.delta_groups = field(kDeltaGroupsKey, split_list);
  p.force_groups = field(kForceGroupsKey, split_list);
  p.angle_groups = field(kAngleGroupsKey, split_list);
  p.length_groups = field(kLengthGroupsKey, split_list);
  p.control_commands = field(kControlCommandsKey, split_list);
  p.board_group = field(kBoardGroupKey, [](const std::string& s) {
    if (!s.empty() && !is_name(s)) throw std::invalid_argument("'" + s + "' is not a group name");
    return s;
  });
  p.contact_sums = field(kContactSumsKey, parse_contact_sums);
  return p;
}

}  // namespace hadynet::datalog
