// A small command-line option parser shared by the hadynet subcommands:
// declared options give the --help text and strict parsing (unknown options,
// missing or malformed values are errors that name the option).
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "firmware/core/model_contract.h"

namespace hadynet::cli {

class Options {
 public:
  // `program` names the executable in the usage line and messages; `command`
  // may be empty for a program without subcommands (hadynet-codegen).
  Options(std::string command, std::string summary, std::string usage,
          std::string program = "hadynet");

  // Declares --name VALUE (or a flag with no value). `help` ends up in --help.
  void value(const std::string& name, const std::string& metavar, const std::string& help,
             std::optional<std::string> default_value = std::nullopt);
  void flag(const std::string& name, const std::string& help);
  // A repeatable --name VALUE.
  void repeated(const std::string& name, const std::string& metavar, const std::string& help);

  // Parses argv (after the subcommand). Returns false and prints to stderr on
  // error; sets help_requested() on -h/--help (after printing the help).
  bool parse(int argc, char** argv);
  bool help_requested() const { return help_; }
  std::string help_text() const;

  bool has(const std::string& name) const;
  std::string get(const std::string& name) const;  // value or default
  const std::vector<std::string>& all(const std::string& name) const;
  const std::vector<std::string>& positional() const { return positional_; }
  // Typed getters: print an error naming the option and return nullopt.
  std::optional<long long> get_int(const std::string& name, long long min, long long max) const;
  std::optional<double> get_double(const std::string& name, double min, double max) const;
  // "q15" or "f32" (firmware::parse_numeric); prints the error otherwise.
  std::optional<firmware::Numeric> get_numeric(const std::string& name) const;

 private:
  struct Spec {
    std::string metavar, help;
    std::optional<std::string> default_value;
    bool takes_value = true, repeatable = false;
  };
  std::string program_name() const;  // "hadynet train", "hadynet-codegen"

  std::string command_, summary_, usage_, program_;
  std::vector<std::string> order_;
  std::map<std::string, Spec> specs_;
  std::map<std::string, std::vector<std::string>> values_;
  std::vector<std::string> positional_;
  bool help_ = false;
};

}  // namespace hadynet::cli
