// From recorded logs to HADYNET's signals (docs/architecture.md §2; docs/method.md, "Windows and standardisation").
//
// Nothing here knows the hand: the channels come from the log header.
//   y_t : every observed group (every numbered group but "u"), header order
//   u_t : the "u" group (change of target per step; u_t acts on y_{t+1}, ...)
//   x_t : per observed group in header order, the group at t, followed, for
//         the "delta groups" only, by the group at t minus the group at t-1.
//         With the hand's logs and delta groups {l, th} this is the paper's
//         x = (l, dl, f, fc, th, dth); x_t exists for t >= 1.
// `aux_*` columns are not model inputs (the residual loop may add them).
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "datalog/log_table.h"
#include "datalog/robot_profile.h"

namespace hadynet::trainer {

// Channel names of x, u and y. Equal layouts mean interchangeable logs.
struct FeatureLayout {
  std::vector<std::string> y_names;       // e.g. l0..l7, f0..f7, fc0..fc8, th0, th1
  std::vector<std::string> u_names;       // u0..u7
  std::vector<std::string> x_names;       // l0..l7, dl0..dl7, f0.., fc0.., th0, th1, dth0, dth1
  std::vector<std::string> delta_groups;  // prefixes whose differences are in x
  // For each x channel: its index in y, and whether it is a difference.
  std::vector<int> x_source;
  std::vector<bool> x_is_delta;

  bool operator==(const FeatureLayout&) const = default;
};

// Group of a numbered channel name: its prefix without the index ("fc3" ->
// "fc", "dl0" -> "dl").
std::string channel_group(const std::string& name);

// Layout of a log's header. Throws std::runtime_error naming `file` if the
// log has no "u" group, or a delta group is not an observed group.
FeatureLayout feature_layout(const datalog::LogTable& table, const std::string& file,
                             const std::vector<std::string>& delta_groups);

// Rebuilds a layout from stored channel names (model file). Throws
// std::runtime_error if x_names does not follow the rules above for y_names.
FeatureLayout feature_layout_from_names(std::vector<std::string> y_names,
                                        std::vector<std::string> u_names,
                                        std::vector<std::string> delta_groups);

// One log in physical units, columns per time step.
struct LogSequence {
  std::string file;    // path, for messages
  std::string state;   // dynamics-state id (metadata "state"; the file stem if absent)
  std::string object;  // metadata "object" ("" if absent)
  Eigen::MatrixXd y;   // y_names.size() x T
  Eigen::MatrixXd u;   // u_names.size() x T

  int steps() const { return static_cast<int>(y.cols()); }
};

// Extracts y and u of `layout` from a log, by column name; a command channel
// the log lacks is computed when its name states a derivation from a logged
// command (sign_u0, hyst_u0: derived_inputs.h). Throws std::runtime_error
// naming the file and the first missing channel.
LogSequence log_sequence(const datalog::LogTable& table, const std::string& file,
                         const FeatureLayout& layout);

// Reads and checks a log (datalog::read_log) and extracts it. LogError and
// std::runtime_error name the file.
LogSequence read_sequence(const std::string& path, const FeatureLayout& layout);

// x_t of a sequence in physical units; requires 1 <= t < steps().
Eigen::VectorXd initial_state(const FeatureLayout& layout, const LogSequence& seq, int t);

// Every *.csv file under each argument (a file is taken as is; a folder is
// searched recursively), sorted by path, duplicates removed. Throws
// std::runtime_error for a missing path or when nothing is found.
std::vector<std::string> expand_log_paths(const std::vector<std::string>& args);

// The delta groups for training, from the option's `choice` and the first log:
//   "auto"  the log's `delta_groups` metadata (none when it has none);
//   "none"  no delta groups;
//   else    a comma-separated list of observed groups.
// Throws std::invalid_argument on an empty list item.
std::vector<std::string> delta_groups_for(const std::string& choice, const datalog::LogTable& first);

// The robot profile the logs carry (datalog/robot_profile.h), with the delta
// groups `choice` gives (delta_groups_for). Throws datalog::LogError naming
// `file` on malformed profile metadata.
datalog::RobotProfile training_profile(const std::string& choice, const datalog::LogTable& first,
                                       const std::string& file);

// Every log of a training set must carry the first log's profile (with
// "auto", the delta groups too): throws std::runtime_error naming `file`, the
// first differing key and `first_file` when `table`'s differs.
void check_profile_metadata(const std::string& choice, const datalog::LogTable& first,
                            const std::string& first_file, const datalog::LogTable& table,
                            const std::string& file);

// Every log of a training set must have the first log's control period
// (metadata dt_s, to within 1e-9 relative: the network learns one step of
// one length): throws std::runtime_error naming both files and periods.
void check_same_period(const datalog::LogTable& first, const std::string& first_file,
                       const datalog::LogTable& table, const std::string& file);

}  // namespace hadynet::trainer
