#include "trainer/log_dataset.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include "datalog/log_limits.h"
#include "datalog/log_reader.h"
#include "datalog/log_rules.h"
#include "trainer/derived_inputs.h"

namespace hadynet::trainer {

namespace {

bool contains(const std::vector<std::string>& v, const std::string& s) {
  return std::find(v.begin(), v.end(), s) != v.end();
}


void add_x_channels(FeatureLayout& layout) {
  layout.x_names.clear();
  layout.x_source.clear();
  layout.x_is_delta.clear();
  const auto& y = layout.y_names;
  for (std::size_t i = 0; i < y.size();) {
    const std::string group = channel_group(y[i]);
    std::size_t end = i;
    while (end < y.size() && channel_group(y[end]) == group) ++end;
    for (std::size_t j = i; j < end; ++j) {
      layout.x_names.push_back(y[j]);
      layout.x_source.push_back(static_cast<int>(j));
      layout.x_is_delta.push_back(false);
    }
    if (contains(layout.delta_groups, group)) {
      for (std::size_t j = i; j < end; ++j) {
        layout.x_names.push_back("d" + y[j]);
        layout.x_source.push_back(static_cast<int>(j));
        layout.x_is_delta.push_back(true);
      }
    }
    i = end;
  }
}

void check_delta_groups(const FeatureLayout& layout, const std::string& where) {
  for (const std::string& g : layout.delta_groups) {
    const bool found = std::any_of(layout.y_names.begin(), layout.y_names.end(),
                                   [&](const std::string& n) { return channel_group(n) == g; });
    if (!found) {
      throw std::runtime_error(where + ": delta group '" + g +
                               "' is not an observed channel group of this log");
    }
  }
}

}  // namespace

std::string channel_group(const std::string& name) {
  std::size_t end = name.size();
  while (end > 0 && name[end - 1] >= '0' && name[end - 1] <= '9') --end;
  return name.substr(0, end);
}

FeatureLayout feature_layout(const datalog::LogTable& table, const std::string& file,
                             const std::vector<std::string>& delta_groups) {
  const datalog::ChannelLayout channels = datalog::channel_layout(table, file);
  if (!channels.command) {
    throw std::runtime_error(file + ": no command channels (u0, u1, ...); HADYNET needs commands");
  }
  FeatureLayout layout;
  for (const auto& group : channels.observed)
    for (std::size_t c : group.columns) layout.y_names.push_back(table.columns[c]);
  for (std::size_t c : channels.command->columns) layout.u_names.push_back(table.columns[c]);
  layout.delta_groups = delta_groups;
  check_delta_groups(layout, file);
  add_x_channels(layout);
  return layout;
}

FeatureLayout feature_layout_from_names(std::vector<std::string> y_names,
                                        std::vector<std::string> u_names,
                                        std::vector<std::string> delta_groups) {
  FeatureLayout layout;
  layout.y_names = std::move(y_names);
  layout.u_names = std::move(u_names);
  layout.delta_groups = std::move(delta_groups);
  if (layout.y_names.empty() || layout.u_names.empty()) {
    throw std::runtime_error("feature layout: no observed or no command channels");
  }
  check_delta_groups(layout, "feature layout");
  add_x_channels(layout);
  return layout;
}

LogSequence log_sequence(const datalog::LogTable& table, const std::string& file,
                         const FeatureLayout& layout) {
  // Column of each name; a command channel the log lacks may be derived from
  // another command (derived_inputs.h): kDerived, filled below.
  constexpr std::size_t kDerived = static_cast<std::size_t>(-1);
  const auto columns_of = [&](const std::vector<std::string>& names, bool allow_derived) {
    std::vector<std::size_t> cols;
    for (const std::string& n : names) {
      const auto c = table.column_index(n);
      if (!c && allow_derived && derived_input_column(table, n)) {
        cols.push_back(kDerived);
        continue;
      }
      if (!c) {
        throw std::runtime_error(file + ": no column '" + n +
                                 "'; the model's channels must all be in the log");
      }
      cols.push_back(*c);
    }
    return cols;
  };
  const std::vector<std::size_t> y_cols = columns_of(layout.y_names, false);
  const std::vector<std::size_t> u_cols = columns_of(layout.u_names, true);
  const Eigen::Index T = static_cast<Eigen::Index>(table.rows());
  std::vector<std::size_t> signal_cols = y_cols;
  for (const std::size_t c : u_cols)
    if (c != kDerived) signal_cols.push_back(c);
  datalog::check_magnitudes(table, signal_cols, datalog::kMaxSignalMagnitude, file,
                            "the trainer computes in float32 (docs/input-limits.md)");

  LogSequence seq;
  seq.file = file;
  seq.state = table.metadata.get("state").value_or(std::filesystem::path(file).stem().string());
  seq.object = table.metadata.get("object").value_or("");
  seq.y.resize(static_cast<Eigen::Index>(y_cols.size()), T);
  seq.u.resize(static_cast<Eigen::Index>(u_cols.size()), T);
  for (Eigen::Index t = 0; t < T; ++t) {
    const auto row = static_cast<std::size_t>(t);
    for (std::size_t i = 0; i < y_cols.size(); ++i)
      seq.y(static_cast<Eigen::Index>(i), t) = table.at(row, y_cols[i]);
    for (std::size_t i = 0; i < u_cols.size(); ++i)
      if (u_cols[i] != kDerived) seq.u(static_cast<Eigen::Index>(i), t) = table.at(row, u_cols[i]);
  }
  for (std::size_t i = 0; i < u_cols.size(); ++i) {
    if (u_cols[i] != kDerived) continue;
    const std::vector<double> v = *derived_input_column(table, layout.u_names[i]);
    for (Eigen::Index t = 0; t < T; ++t) seq.u(static_cast<Eigen::Index>(i), t) = v[static_cast<std::size_t>(t)];
  }
  return seq;
}

LogSequence read_sequence(const std::string& path, const FeatureLayout& layout) {
  const datalog::LogTable table = datalog::read_log(path);
  datalog::channel_layout(table, path);  // header rules (read_log checks them too)
  return log_sequence(table, path, layout);
}

Eigen::VectorXd initial_state(const FeatureLayout& layout, const LogSequence& seq, int t) {
  if (t < 1 || t >= seq.steps()) {
    throw std::out_of_range(seq.file + ": x_t needs 1 <= t < " + std::to_string(seq.steps()) +
                            ", got t = " + std::to_string(t));
  }
  Eigen::VectorXd x(static_cast<Eigen::Index>(layout.x_names.size()));
  for (std::size_t i = 0; i < layout.x_names.size(); ++i) {
    const Eigen::Index src = layout.x_source[i];
    x(static_cast<Eigen::Index>(i)) =
        layout.x_is_delta[i] ? seq.y(src, t) - seq.y(src, t - 1) : seq.y(src, t);
  }
  return x;
}

std::vector<std::string> expand_log_paths(const std::vector<std::string>& args) {
  namespace fs = std::filesystem;
  std::vector<std::string> paths;
  for (const std::string& arg : args) {
    std::error_code ec;
    const fs::file_status st = fs::status(arg, ec);
    if (ec || !fs::exists(st)) throw std::runtime_error(arg + ": no such file or folder");
    if (fs::is_directory(st)) {
      std::size_t found = 0;
      for (const auto& entry : fs::recursive_directory_iterator(arg)) {
        if (entry.is_regular_file() && entry.path().extension() == ".csv") {
          paths.push_back(entry.path().string());
          ++found;
        }
      }
      if (found == 0) throw std::runtime_error(arg + ": folder holds no *.csv logs");
    } else {
      paths.push_back(arg);
    }
  }
  std::sort(paths.begin(), paths.end());
  paths.erase(std::unique(paths.begin(), paths.end()), paths.end());
  if (paths.empty()) throw std::runtime_error("no logs given");
  return paths;
}

std::vector<std::string> delta_groups_for(const std::string& choice, const datalog::LogTable& first) {
  if (choice != "auto") return datalog::split_list(choice);
  const auto groups = first.metadata.get(datalog::kDeltaGroupsKey);
  return groups ? datalog::split_list(*groups) : std::vector<std::string>{};
}

datalog::RobotProfile training_profile(const std::string& choice, const datalog::LogTable& first,
                                       const std::string& file) {
  datalog::RobotProfile profile = datalog::read_profile(first.metadata, file);
  profile.delta_groups = delta_groups_for(choice, first);
  return profile;
}

void check_profile_metadata(const std::string& choice, const datalog::LogTable& first,
                            const std::string& first_file, const datalog::LogTable& table,
                            const std::string& file) {
  const char* keys[] = {datalog::kDeltaGroupsKey,     datalog::kForceGroupsKey, datalog::kAngleGroupsKey,
                        datalog::kLengthGroupsKey,    datalog::kControlCommandsKey, datalog::kBoardGroupKey,
                        datalog::kContactSumsKey};
  for (const char* key : keys) {
    if (choice != "auto" && std::string_view(key) == datalog::kDeltaGroupsKey) continue;
    const auto expected = first.metadata.get(key);
    const auto here = table.metadata.get(key);
    if (here == expected) continue;
    throw std::runtime_error(file + ": metadata '" + key + "' is " + (here ? "'" + *here + "'" : "absent") + " but " +
                             (expected ? "'" + *expected + "'" : "absent") + " in " + first_file +
                             (std::string_view(key) == datalog::kDeltaGroupsKey ? "; give --delta-groups"
                                                                                 : "; the logs come from different robots"));
  }
}

void check_same_period(const datalog::LogTable& first, const std::string& first_file,
                       const datalog::LogTable& table, const std::string& file) {
  const double expected = datalog::log_dt_s(first, first_file);
  const double here = datalog::log_dt_s(table, file);
  if (std::abs(here - expected) <= 1e-9 * expected) return;
  throw std::runtime_error(file + ": metadata 'dt_s' is " + datalog::rules::format_number(here) + " s but " +
                           datalog::rules::format_number(expected) + " s in " + first_file +
                           "; a model learns one control period: train on logs of one dt_s");
}

}  // namespace hadynet::trainer
