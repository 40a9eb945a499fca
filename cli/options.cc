#include "cli/options.h"

#include <charconv>
#include <cmath>
#include <cstdio>

namespace hadynet::cli {

Options::Options(std::string command, std::string summary, std::string usage, std::string program)
    : command_(std::move(command)),
      summary_(std::move(summary)),
      usage_(std::move(usage)),
      program_(std::move(program)) {}

std::string Options::program_name() const {
  return command_.empty() ? program_ : program_ + " " + command_;
}

void Options::value(const std::string& name, const std::string& metavar, const std::string& help,
                    std::optional<std::string> default_value) {
  order_.push_back(name);
  specs_[name] = Spec{metavar, help, std::move(default_value), true, false};
}

void Options::flag(const std::string& name, const std::string& help) {
  order_.push_back(name);
  specs_[name] = Spec{"", help, std::nullopt, false, false};
}

void Options::repeated(const std::string& name, const std::string& metavar, const std::string& help) {
  order_.push_back(name);
  specs_[name] = Spec{metavar, help, std::nullopt, true, true};
}

std::string Options::help_text() const {
  std::string out = "usage: " + program_name() + " " + usage_ + "\n\n" + summary_ + "\n\noptions:\n";
  for (const auto& name : order_) {
    const Spec& s = specs_.at(name);
    std::string left = "  --" + name + (s.takes_value ? " " + s.metavar : "");
    if (left.size() < 26) left.resize(26, ' '); else left += "\n" + std::string(26, ' ');
    // A help text's own line breaks continue in the help column (lines it
    // indents itself stay as they are).
    std::string help;
    for (std::size_t i = 0; i < s.help.size(); ++i) {
      help += s.help[i];
      if (s.help[i] == '\n' && i + 1 < s.help.size() && s.help[i + 1] != ' ') help += std::string(26, ' ');
    }
    out += left + help;
    if (s.default_value) out += " (default: " + *s.default_value + ")";
    if (s.repeatable) out += " (repeatable)";
    out += "\n";
  }
  out += "  -h, --help              show this help\n";
  return out;
}

bool Options::parse(int argc, char** argv) {
  for (int i = 0; i < argc; ++i) {
    std::string arg = argv[i];
    if (arg == "-h" || arg == "--help") {
      help_ = true;
      std::fputs(help_text().c_str(), stdout);
      return true;
    }
    if (arg.rfind("--", 0) != 0 || arg.size() == 2) {
      positional_.push_back(arg);
      continue;
    }
    std::string name = arg.substr(2), inline_value;
    bool has_inline = false;
    if (const auto eq = name.find('='); eq != std::string::npos) {
      inline_value = name.substr(eq + 1);
      name = name.substr(0, eq);
      has_inline = true;
    }
    const auto it = specs_.find(name);
    if (it == specs_.end()) {
      std::fprintf(stderr, "%s: unknown option '--%s' (see --help)\n", program_name().c_str(), name.c_str());
      return false;
    }
    if (!it->second.takes_value) {
      if (has_inline) {
        std::fprintf(stderr, "%s: option '--%s' takes no value\n", program_name().c_str(), name.c_str());
        return false;
      }
      values_[name].push_back("1");
      continue;
    }
    if (!has_inline) {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "%s: option '--%s' needs a value %s\n", program_name().c_str(), name.c_str(),
                     it->second.metavar.c_str());
        return false;
      }
      inline_value = argv[++i];
    }
    if (!it->second.repeatable && values_.count(name)) {
      std::fprintf(stderr, "%s: option '--%s' given twice\n", program_name().c_str(), name.c_str());
      return false;
    }
    values_[name].push_back(inline_value);
  }
  return true;
}

bool Options::has(const std::string& name) const { return values_.count(name) > 0; }

std::string Options::get(const std::string& name) const {
  if (const auto it = values_.find(name); it != values_.end()) return it->second.back();
  const auto& spec = specs_.at(name);
  return spec.default_value.value_or("");
}

const std::vector<std::string>& Options::all(const std::string& name) const {
  static const std::vector<std::string> kEmpty;
  const auto it = values_.find(name);
  return it == values_.end() ? kEmpty : it->second;
}

std::optional<long long> Options::get_int(const std::string& name, long long min, long long max) const {
  const std::string text = get(name);
  long long v = 0;
  auto [p, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
  if (ec != std::errc() || p != text.data() + text.size() || v < min || v > max) {
    std::fprintf(stderr, "%s: --%s: expected a whole number in %lld..%lld, got '%s'\n", program_name().c_str(),
                 name.c_str(), min, max, text.c_str());
    return std::nullopt;
  }
  return v;
}

std::optional<firmware::Numeric> Options::get_numeric(const std::string& name) const {
  const std::string text = get(name);
  firmware::Numeric n{};
  if (!firmware::parse_numeric(text, n)) {
    std::fprintf(stderr, "%s: --%s must be q15 or f32, not '%s'\n", program_name().c_str(), name.c_str(), text.c_str());
    return std::nullopt;
  }
  return n;
}

std::optional<double> Options::get_double(const std::string& name, double min, double max) const {
  const std::string text = get(name);
  double v = 0;
  auto [p, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
  if (ec != std::errc() || p != text.data() + text.size() || !std::isfinite(v) || v < min || v > max) {
    std::fprintf(stderr, "%s: --%s: expected a number in %g..%g, got '%s'\n", program_name().c_str(), name.c_str(),
                 min, max, text.c_str());
    return std::nullopt;
  }
  return v;
}

}  // namespace hadynet::cli
