// The one command-line parser of the tools (src/tools/cli_args.h): types, ranges, no
// narrowing, unknown options, --help from the table.
#include "../../src/tools/cli_args.h"

#include <gtest/gtest.h>

#include <climits>
#include <vector>

using namespace mono_plane_detection;
using cli::Parser;
using cli::toInteger;
using cli::toNumber;

namespace {

// Parses words as a command line ("prog" first); true = go on, false = --help.
bool parse(Parser& parser, std::vector<const char*> words) {
  words.insert(words.begin(), "prog");
  return parser.parseOrThrow(static_cast<int>(words.size()), words.data());
}

}  // namespace

TEST(CliArgs, IntegersAreWholeInRangeAndNeverNarrowed) {
  EXPECT_EQ(toInteger<int>("42", 1, 100), 42);
  EXPECT_EQ(toInteger<int>("-7", -10, 10), -7);
  EXPECT_FALSE(toInteger<int>("0", 1, 100));     // below the range
  EXPECT_FALSE(toInteger<int>("101", 1, 100));   // above
  EXPECT_FALSE(toInteger<int>("4.5", 1, 100));   // not whole
  EXPECT_FALSE(toInteger<int>("12abc", 1, 100));
  EXPECT_FALSE(toInteger<int>("", 1, 100));
  // Values a long holds but an int does not: refused, not truncated (issue 15 item 10:
  // 4294967295 became -1 or 0 through static_cast<int>).
  EXPECT_FALSE(toInteger<int>("2147483648", INT_MIN, INT_MAX));
  EXPECT_FALSE(toInteger<int>("4294967295", INT_MIN, INT_MAX));
  EXPECT_FALSE(toInteger<int>("4294967296", INT_MIN, INT_MAX));
  EXPECT_EQ(toInteger<int>("2147483647", INT_MIN, INT_MAX), INT_MAX);
  EXPECT_FALSE(toInteger<long long>("99999999999999999999", LLONG_MIN, LLONG_MAX));
  // An unsigned never takes a minus sign (strtoul would wrap "-1" to the maximum).
  EXPECT_FALSE(toInteger<unsigned>("-1", 0u, UINT_MAX));
  EXPECT_FALSE(toInteger<unsigned>(" -1", 0u, UINT_MAX));
  EXPECT_EQ(toInteger<unsigned>("4294967295", 0u, UINT_MAX), UINT_MAX);
  EXPECT_FALSE(toInteger<unsigned>("4294967296", 0u, UINT_MAX));
  EXPECT_FALSE(toInteger<int>(std::string("5\0junk", 6), 1, 100));  // embedded NUL
}

TEST(CliArgs, NumbersAreFiniteAndInRange) {
  EXPECT_EQ(toNumber("2.5", 0, 10), 2.5);
  EXPECT_EQ(toNumber("-1e-3", -1, 1), -1e-3);
  EXPECT_FALSE(toNumber("nan", -1e9, 1e9));
  EXPECT_FALSE(toNumber("inf", -1e300, 1e300));
  EXPECT_FALSE(toNumber("1e999", -1e300, 1e300));  // overflow
  EXPECT_FALSE(toNumber("1e300", 0, 1000));        // issue 15 item 13: --fps 1e300
  EXPECT_FALSE(toNumber("3x", 0, 10));
  EXPECT_FALSE(toNumber(std::string("1.0\0junk", 8), 0, 10));
  const auto tiny = toNumber("1e-320", 0, 1);  // subnormal: finite
  ASSERT_TRUE(tiny);
  EXPECT_GT(*tiny, 0);
}

TEST(CliArgs, TableSetsTypedTargetsAndKeepsDefaults) {
  int frames = 300;
  unsigned seed = 1;
  double fps = 30;
  std::string mode = "a", path, out = "x";
  bool quiet = false, ceiling = true;
  Parser p("prog", "[options] FILE", "does things");
  p.positional("FILE", &path, "input")
      .integer("frames", &frames, 1, 1000, "images")
      .integer<unsigned>("seed", &seed, 0, UINT_MAX, "seed")
      .number("fps", &fps, 0.1, 100.0, "rate")
      .choice("mode", &mode, {"a", "b"}, "mode")
      .text("out", &out, "output")
      .flag("quiet", &quiet, "quiet")
      .flag("no-ceiling", &ceiling, "no ceiling", false);
  EXPECT_TRUE(parse(p, {"--frames", "12", "--fps=2.5", "in.txt",
                        "--mode", "b", "--quiet", "--no-ceiling", "--seed", "4294967295"}));
  EXPECT_EQ(frames, 12);
  EXPECT_EQ(fps, 2.5);
  EXPECT_EQ(path, "in.txt");
  EXPECT_EQ(mode, "b");
  EXPECT_TRUE(quiet);
  EXPECT_FALSE(ceiling);
  EXPECT_EQ(seed, UINT_MAX);
  EXPECT_EQ(out, "x");  // not given: default kept
}

TEST(CliArgs, BadCommandLinesThrowUsageErrorsNamingTheOption) {
  int frames = 300;
  double k1 = 0;
  std::string path, mode = "a";
  auto make = [&]() {
    Parser p("prog", "[options] FILE", "");
    p.positional("FILE", &path, "input")
        .integer("frames", &frames, 1, 1000, "images")
        .number("k1", &k1, -10.0, 10.0, "distortion")
        .choice("mode", &mode, {"a", "b"}, "mode");
    return p;
  };
  auto message = [&](std::vector<const char*> words) -> std::string {
    Parser p = make();
    try {
      parse(p, words);
    } catch (const cli::UsageError& e) {
      return e.what();
    }
    return "";
  };
  EXPECT_NE(message({"--frames", "0", "f"}).find("--frames"), std::string::npos);
  EXPECT_NE(message({"--frames", "2147483648", "f"}).find("[1, 1000]"), std::string::npos);
  EXPECT_NE(message({"--frobnicate", "1", "f"}).find("frobnicate"), std::string::npos);
  EXPECT_NE(message({"--fr", "5", "f"}), "");  // no guessing of abbreviations
  EXPECT_NE(message({"--frames", "1", "--frames", "2", "f"}), "");  // given twice
  EXPECT_NE(message({"--frames", "f"}), "");   // value missing
  EXPECT_NE(message({}).find("FILE"), std::string::npos);  // positional required
  EXPECT_NE(message({"a", "b"}), "");                        // one positional too many
  EXPECT_NE(message({"--mode", "c", "f"}).find("a|b"), std::string::npos);
  EXPECT_NE(message({"--k1", "nan", "f"}), "");
  EXPECT_EQ(message({"--k1", "-0.5", "f"}), "");  // a negative value is a value
  EXPECT_EQ(k1, -0.5);
}

TEST(CliArgs, HelpComesFromTheTableAndExitsZero) {
  int frames = 300;
  std::string path;
  Parser p("prog", "[options] FILE", "  does things", "exit codes: 0, 2\n");
  p.positional("FILE", &path, "input").integer("frames", &frames, 1, 1000, "images to render");
  EXPECT_FALSE(parse(p, {"--help"}));
  EXPECT_FALSE(parse(p, {"-h"}));
  const std::string usage = p.usage();
  EXPECT_EQ(usage.rfind("usage: prog [options] FILE\n", 0), 0u) << usage;
  EXPECT_NE(usage.find("--frames N"), std::string::npos);
  EXPECT_NE(usage.find("images to render (default 300, range [1, 1000])"), std::string::npos);
  EXPECT_NE(usage.find("--help"), std::string::npos);
  EXPECT_NE(usage.find("exit codes"), std::string::npos);
  std::vector<const char*> help = {"prog", "--help"};
  testing::internal::CaptureStdout();
  const auto code = p.parse(2, help.data());
  const std::string printed = testing::internal::GetCapturedStdout();
  ASSERT_TRUE(code);
  EXPECT_EQ(*code, 0);
  EXPECT_EQ(printed, usage);
  std::vector<const char*> bad = {"prog", "--nope"};
  testing::internal::CaptureStderr();
  const auto bad_code = Parser(p).parse(2, bad.data());
  const std::string complaint = testing::internal::GetCapturedStderr();
  ASSERT_TRUE(bad_code);
  EXPECT_EQ(*bad_code, 2);
  EXPECT_NE(complaint.find("usage: prog"), std::string::npos);
}

// detect_target IMAGE...: every remaining argument, options before or after them.
TEST(CliArgs, VariadicPositionalsTakeEveryRemainingArgument) {
  std::vector<std::string> images;
  bool json = false;
  Parser p("prog", "[options] IMAGE...", "");
  p.positionals("IMAGE", &images, "images").flag("json", &json, "JSON");
  EXPECT_TRUE(parse(p, {"a.png", "--json", "b.png", "c.jpg"}));
  EXPECT_EQ(images, (std::vector<std::string>{"a.png", "b.png", "c.jpg"}));
  EXPECT_TRUE(json);
  std::vector<std::string> none;
  Parser q("prog", "IMAGE...", "");
  q.positionals("IMAGE", &none, "images");
  EXPECT_THROW(parse(q, {}), cli::UsageError);  // at least one
  std::vector<std::string> optional;
  Parser r("prog", "[IMAGE...]", "");
  r.positionals("IMAGE", &optional, "images", false);
  EXPECT_TRUE(parse(r, {}));
  EXPECT_TRUE(optional.empty());
}
