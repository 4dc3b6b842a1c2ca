// The one command-line parser of the package's programs: each program declares its
// options once in a table (name, type, default, range, help) and gets from it the
// parsing, the typed and range-checked values and the --help text.
//
// The syntax (--name VALUE, --name=VALUE, positionals, unknown or repeated options) is
// boost::program_options, which ROS already pulls in. Its typed values are not used:
// boost::lexical_cast accepts "-1" for an unsigned (it wraps) and "nan" for a double, and
// it knows no ranges. Every value is taken as text and converted here: the whole text,
// in range, into the target's own type, so nothing is narrowed on the way.
//
// Exit codes shared by every program: 0 done (and after --help), 2 bad usage or input.
#pragma once

#include <algorithm>
#include <boost/program_options.hpp>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <limits>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

namespace mono_plane_detection {
namespace cli {

// A command line or an input the program cannot use: exit code 2, message for the user.
struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

constexpr int kExitUsage = 2;

// The whole text is one integer of type T within [lo, hi]. Out of T's range is refused,
// not wrapped or truncated; a '-' is refused for an unsigned type.
template <class T>
std::optional<T> toInteger(const std::string& text, T lo, T hi) {
  static_assert(std::is_integral<T>::value, "integer types only");
  if (text.empty() || text.find('\0') != std::string::npos) return std::nullopt;
  const char* begin = text.c_str();
  char* end = nullptr;
  errno = 0;
  if (std::is_signed<T>::value) {
    const long long v = std::strtoll(begin, &end, 10);
    if (errno || end != begin + text.size()) return std::nullopt;
    if (v < static_cast<long long>(lo) || v > static_cast<long long>(hi)) return std::nullopt;
    return static_cast<T>(v);
  }
  size_t first = 0;
  while (first < text.size() && std::isspace(static_cast<unsigned char>(text[first]))) ++first;
  if (first < text.size() && text[first] == '-') return std::nullopt;
  const unsigned long long v = std::strtoull(begin, &end, 10);
  if (errno || end != begin + text.size()) return std::nullopt;
  if (v < static_cast<unsigned long long>(lo) || v > static_cast<unsigned long long>(hi))
    return std::nullopt;
  return static_cast<T>(v);
}

// The whole text is one finite number within [lo, hi]. A subnormal (1e-320) is a finite
// number: strtod's ERANGE for underflow is not an error here, its overflow is (inf).
inline std::optional<double> toNumber(const std::string& text, double lo, double hi) {
  if (text.empty() || text.find('\0') != std::string::npos) return std::nullopt;
  const char* begin = text.c_str();
  char* end = nullptr;
  errno = 0;
  const double v = std::strtod(begin, &end);
  if (end != begin + text.size() || !std::isfinite(v)) return std::nullopt;
  if (!(v >= lo && v <= hi)) return std::nullopt;
  return v;
}

class Parser {
 public:
  // synopsis: what follows the program's name in the usage line; about: what it does;
  // epilog: printed after the options (input format, exit codes).
  Parser(std::string program, std::string synopsis, std::string about, std::string epilog = "")
      : program_(std::move(program)),
        synopsis_(std::move(synopsis)),
        about_(std::move(about)),
        epilog_(std::move(epilog)) {}

  // An integer option into *target (its type: int, unsigned, long...), within [lo, hi].
  template <class T>
  Parser& integer(const std::string& name, T* target, T lo, T hi, const std::string& help,
                  const std::string& value_name = "N") {
    const std::string range = "[" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
    add(name, value_name, help, std::to_string(*target), range,
        [=](const std::string& text) {
          const std::optional<T> v = toInteger<T>(text, lo, hi);
          if (!v) return "needs a whole number in " + range + ", not '" + text + "'";
          *target = *v;
          return std::string();
        });
    return *this;
  }

  // A finite number option within [lo, hi].
  Parser& number(const std::string& name, double* target, double lo, double hi,
                 const std::string& help, const std::string& value_name = "X") {
    const std::string range = "[" + format(lo) + ", " + format(hi) + "]";
    add(name, value_name, help, format(*target), range, [=](const std::string& text) {
      const std::optional<double> v = toNumber(text, lo, hi);
      if (!v) return "needs a finite number in " + range + ", not '" + text + "'";
      *target = *v;
      return std::string();
    });
    return *this;
  }

  // One of a fixed list of words.
  Parser& choice(const std::string& name, std::string* target, std::vector<std::string> choices,
                 const std::string& help) {
    std::string list;
    for (const std::string& c : choices) list += (list.empty() ? "" : "|") + c;
    add(name, list, help, *target, "", [=](const std::string& text) {
      for (const std::string& c : choices)
        if (text == c) {
          *target = text;
          return std::string();
        }
      return "must be one of " + list + ", not '" + text + "'";
    });
    return *this;
  }

  // Free text (a path, a topic).
  Parser& text(const std::string& name, std::string* target, const std::string& help,
               const std::string& value_name = "TEXT") {
    add(name, value_name, help, *target, "", [=](const std::string& text) {
      if (text.empty()) return std::string("needs a non-empty value");
      *target = text;
      return std::string();
    });
    return *this;
  }

  // A switch without a value: sets *target to `value` when given.
  Parser& flag(const std::string& name, bool* target, const std::string& help,
               bool value = true) {
    Option o;
    o.name = name;
    o.help = help;
    o.is_flag = true;
    o.set = [=](const std::string&) {
      *target = value;
      return std::string();
    };
    options_.push_back(o);
    return *this;
  }

  // The next argument that is not an option (in declaration order).
  Parser& positional(const std::string& name, std::string* target, const std::string& help,
                     bool required = true) {
    positionals_.push_back({name, help, required, target});
    return *this;
  }

  // Every remaining argument that is not an option (last, after the single positionals):
  // "IMAGE...". Required: at least one.
  Parser& positionals(const std::string& name, std::vector<std::string>* target,
                      const std::string& help, bool required = true) {
    positionals_.push_back({name, help, required, nullptr, target});
    return *this;
  }

  // Exit code to return now (0 after --help, 2 after a usage error, with the reason and
  // the usage on stderr), or nothing: the targets are set, go on.
  std::optional<int> parse(int argc, const char* const* argv) {
    try {
      if (parseOrThrow(argc, argv)) return std::nullopt;
      std::fputs(usage().c_str(), stdout);
      return 0;
    } catch (const UsageError& e) {
      return fail(e.what());
    }
  }

  // Throws UsageError; false when --help was asked for (nothing else is set then).
  bool parseOrThrow(int argc, const char* const* argv) {
    namespace po = boost::program_options;
    po::options_description all;
    auto adder = all.add_options();
    adder("help,h", "");
    for (const Option& o : options_) {
      if (o.is_flag)
        adder(o.name.c_str(), po::bool_switch(), "");
      else
        adder(o.name.c_str(), po::value<std::string>(), "");
    }
    po::positional_options_description order;
    for (const Positional& p : positionals_) {
      if (p.rest) {
        adder(p.name.c_str(), po::value<std::vector<std::string>>(), "");
        order.add(p.name.c_str(), -1);
      } else {
        adder(p.name.c_str(), po::value<std::string>(), "");
        order.add(p.name.c_str(), 1);
      }
    }
    po::variables_map values;
    try {
      po::store(po::command_line_parser(argc, argv)
                    .options(all)
                    .positional(order)
                    .style(po::command_line_style::unix_style ^
                           po::command_line_style::allow_guessing)
                    .run(),
                values);
    } catch (const po::error& e) {
      throw UsageError(e.what());
    }
    if (values.count("help")) return false;
    for (const Option& o : options_) {
      if (!values.count(o.name) || values[o.name].defaulted()) continue;
      if (o.is_flag) {
        if (values[o.name].as<bool>()) o.set("");
        continue;
      }
      const std::string why = o.set(values[o.name].as<std::string>());
      if (!why.empty()) throw UsageError("--" + o.name + " " + why);
    }
    for (const Positional& p : positionals_) {
      if (p.rest && values.count(p.name))
        *p.rest = values[p.name].as<std::vector<std::string>>();
      else if (p.rest && p.required)
        throw UsageError("missing " + p.name);
      else if (p.rest)
        continue;
      else if (values.count(p.name))
        *p.target = values[p.name].as<std::string>();
      else if (p.required)
        throw UsageError("missing " + p.name);
    }
    return true;
  }

  // "program: what" and the usage on stderr; the usage-error exit code.
  int fail(const std::string& what) const {
    std::fprintf(stderr, "%s: %s\n%s", program_.c_str(), what.c_str(), usage().c_str());
    return kExitUsage;
  }

  // The --help text, made from the table.
  std::string usage() const {
    std::ostringstream out;
    out << "usage: " << program_ << " " << synopsis_ << "\n";
    if (!about_.empty()) out << about_ << (about_.back() == '\n' ? "" : "\n");
    for (const Positional& p : positionals_)
      out << "  " << p.name << (p.required ? "" : " (optional)") << ": " << p.help << "\n";
    out << "options:\n";
    std::vector<std::pair<std::string, std::string>> rows;
    for (const Option& o : options_) {
      std::string left = "--" + o.name + (o.is_flag ? "" : " " + o.value_name);
      std::string right = o.help;
      if (!o.is_flag) {
        std::string extra;
        if (!o.default_text.empty()) extra += "default " + o.default_text;
        if (!o.range.empty()) extra += (extra.empty() ? "" : ", ") + std::string("range ") + o.range;
        if (!extra.empty()) right += " (" + extra + ")";
      }
      rows.emplace_back(left, right);
    }
    rows.emplace_back("-h, --help", "print this help and exit 0");
    size_t width = 0;
    for (const auto& r : rows) width = std::max(width, r.first.size());
    for (const auto& r : rows)
      out << "  " << r.first << std::string(width + 2 - r.first.size(), ' ') << r.second << "\n";
    if (!epilog_.empty()) out << epilog_ << (epilog_.back() == '\n' ? "" : "\n");
    return out.str();
  }

  const std::string& program() const { return program_; }

 private:
  struct Option {
    std::string name, value_name, help, default_text, range;
    bool is_flag = false;
    std::function<std::string(const std::string&)> set;  // empty string = accepted
  };
  struct Positional {
    std::string name, help;
    bool required;
    std::string* target;
    std::vector<std::string>* rest = nullptr;  // takes every remaining argument
  };

  void add(const std::string& name, const std::string& value_name, const std::string& help,
           const std::string& default_text, const std::string& range,
           std::function<std::string(const std::string&)> set) {
    Option o;
    o.name = name;
    o.value_name = value_name;
    o.help = help;
    o.default_text = default_text;
    o.range = range;
    o.set = std::move(set);
    options_.push_back(std::move(o));
  }

  static std::string format(double v) {
    char buffer[32];
    std::snprintf(buffer, sizeof buffer, "%g", v);
    return buffer;
  }

  std::string program_, synopsis_, about_, epilog_;
  std::vector<Option> options_;
  std::vector<Positional> positionals_;
};

}  // namespace cli
}  // namespace mono_plane_detection
