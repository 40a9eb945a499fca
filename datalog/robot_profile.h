// What the tools need to know about a robot beyond its logs' channel names:
// which observed groups integrate the commands, which are forces, angles and
// lengths, which commands a stabiliser may move, which group the MCU board
// measures itself, and which force channels sum to a named contact (e.g. the
// fingertips). The plant writes its robot's profile into every log it
// records (metadata keys below, docs/log-format.md); `hadynet train` stores
// the logs' profile in the model file, and codegen, validate and the
// firmware's channel binding take it from there. Options override it, so a
// robot whose logs carry no profile needs options, never code.
//
// Every field may be empty: an empty profile is the generic default (no
// delta groups, no loss classes, every command may move, nothing measured on
// the board, no contact sums).
#ifndef HADYNET_DATALOG_ROBOT_PROFILE_H_
#define HADYNET_DATALOG_ROBOT_PROFILE_H_

#include <string>
#include <vector>

#include "datalog/log_table.h"

namespace hadynet::datalog {

// A named sum of observed channels, e.g. {"tips", {"fc0", ..., "fc4"}}.
struct ContactSum {
  std::string name;                   // [a-z0-9_]+
  std::vector<std::string> channels;  // observed channel names (not groups)
  bool operator==(const ContactSum&) const = default;
};

struct RobotProfile {
  // Observed groups whose step differences are in the model's x (states
  // that integrate the commands, e.g. "l", "th" of the hand).
  std::vector<std::string> delta_groups;
  // Observed groups by physical quantity: forces (N), angles (rad) and
  // lengths (mm). The grasp stabiliser weighs its loss by these classes.
  std::vector<std::string> force_groups;
  std::vector<std::string> angle_groups;
  std::vector<std::string> length_groups;
  // Command channels the grasp stabiliser may change; empty: all.
  std::vector<std::string> control_commands;
  // The observed group the MCU board scans itself (its ADCs): channel k of
  // this group is the board's reading k. Empty: the host sends every channel.
  std::string board_group;
  // Named sums of force channels for statistics (validate).
  std::vector<ContactSum> contact_sums;

  bool empty() const { return *this == RobotProfile{}; }
  bool operator==(const RobotProfile&) const = default;
};

// Log metadata keys of the profile's fields (docs/log-format.md §2).
inline constexpr const char* kDeltaGroupsKey = "delta_groups";
inline constexpr const char* kForceGroupsKey = "force_groups";
inline constexpr const char* kAngleGroupsKey = "angle_groups";
inline constexpr const char* kLengthGroupsKey = "length_groups";
inline constexpr const char* kControlCommandsKey = "control_commands";
inline constexpr const char* kBoardGroupKey = "board_group";
inline constexpr const char* kContactSumsKey = "contact_sums";

// Writes the non-empty fields as metadata (lists comma-separated; contact
// sums space-separated, as `units`: "tips=fc0+fc1 palm=fc5").
void write_profile(const RobotProfile& profile, LogMetadata& metadata);

// Reads the profile's keys from `metadata`; absent keys leave fields empty.
// Throws LogError naming `where` and the key on a malformed value.
RobotProfile read_profile(const LogMetadata& metadata, const std::string& where);

// "a,b,c" <-> {"a","b","c"}; "" and "none" <-> {}. Throws std::invalid_argument
// on an empty item ("a,,b").
std::vector<std::string> split_list(const std::string& text);
std::string join_list(const std::vector<std::string>& items);

// "tips=fc0+fc1 palm=fc5" <-> contact sums. Throws std::invalid_argument
// naming the fault.
std::vector<ContactSum> parse_contact_sums(const std::string& text);
std::string contact_sums_text(const std::vector<ContactSum>& sums);

}  // namespace hadynet::datalog

#endif  // HADYNET_DATALOG_ROBOT_PROFILE_H_
