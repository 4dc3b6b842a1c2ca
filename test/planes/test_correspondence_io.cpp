#include <gtest/gtest.h>
#include <sys/resource.h>

#include <algorithm>

#include <sstream>
#include <streambuf>

#include "mono_plane_detection/planes/correspondence_io.h"

using namespace mono_plane_detection;

namespace {
Correspondences read(const std::string& text) {
  std::istringstream in(text);
  return readCorrespondences(in);
}
// A stream of `size` bytes of "1 " made on the fly, then "\n": a huge line that is
// never held in memory by the test itself.
class RepeatingBuffer : public std::streambuf {
 public:
  explicit RepeatingBuffer(size_t size) : left_(size) {
    for (size_t i = 0; i < sizeof chunk_; ++i) chunk_[i] = i % 2 ? ' ' : '1';
  }

 protected:
  int_type underflow() override {
    if (left_ == 0) {
      if (newline_done_) return traits_type::eof();
      newline_done_ = true;
      chunk_[0] = '\n';
      setg(chunk_, chunk_, chunk_ + 1);
      return chunk_[0];
    }
    const size_t n = std::min(left_, sizeof chunk_);
    left_ -= n;
    setg(chunk_, chunk_, chunk_ + n);
    return chunk_[0];
  }

 private:
  char chunk_[4096];
  size_t left_;
  bool newline_done_ = false;
};

long peakRssKb() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_maxrss;
}

}  // namespace

// Issue 15 item 9. First in this file so that the process's peak memory is still small.
// The old reader copied the line, then every token (about 20 times the line: 17 GB for
// 1 GB) before it counted the fields.
TEST(CorrespondenceIo, AVeryLongLineIsRefusedWithoutHoldingIt) {
  const long before = peakRssKb();
  const size_t line_bytes = 64u << 20;  // 64 MB, 32 M fields
  RepeatingBuffer buffer(line_bytes);
  std::istream in(&buffer);
  const Correspondences c = readCorrespondences(in);
  const long grown_kb = peakRssKb() - before;
  EXPECT_EQ(c.error_line, 1);
  EXPECT_NE(c.error.find("longer than"), std::string::npos) << c.error;
  EXPECT_TRUE(c.view1.empty());
  // Bounded by the per-line limit (64 KiB), not by the line: 8 MB of slack for the
  // allocator and the test framework.
  EXPECT_LT(grown_kb, 8 * 1024) << "peak memory grew " << grown_kb << " kB for a "
                                << (line_bytes >> 20) << " MB line";
}

TEST(CorrespondenceIo, LinesUpToTheLimitAreRead) {
  std::string line = "1 2 3 4 #";
  line += std::string(kMaxCorrespondenceLineBytes - line.size(), 'c');
  auto c = read(line + "\n5 6 7 8\n");
  EXPECT_TRUE(c.error.empty()) << c.error;
  EXPECT_EQ(c.view1.size(), 2u);
  c = read(line + "c\n5 6 7 8\n");  // one byte over
  EXPECT_EQ(c.error_line, 1);
  // Many fields within the limit: counted, named.
  std::string many;
  for (int i = 0; i < 1000; ++i) many += "1 ";
  c = read("1 2 3 4\n" + many + "\n");
  EXPECT_EQ(c.error_line, 2);
  EXPECT_NE(c.error.find("found 1000 fields"), std::string::npos) << c.error;
}

// Issue 15 item 12: a subnormal is a finite number; a NUL inside a token is not a number.
TEST(CorrespondenceIo, SubnormalsAreNumbersAndEmbeddedNulIsNot) {
  auto c = read("1e-320 2 3 -4.9e-324\n");
  EXPECT_TRUE(c.error.empty()) << c.error;
  ASSERT_EQ(c.view1.size(), 1u);
  EXPECT_GT(c.view1[0].x, 0.0);
  EXPECT_LT(c.view2[0].y, 0.0);
  c = read(std::string("1 2 3 4\n1.0\0junk 2 3 4\n", 23));
  EXPECT_EQ(c.error_line, 2) << c.error;
  EXPECT_NE(c.error.find("\\x00"), std::string::npos) << c.error;  // shown, not cut
  c = read(std::string("1 2 3 4\0\n", 9));
  EXPECT_EQ(c.error_line, 1);
}

TEST(CorrespondenceIo, ReadsNumbersCommentsAndBlankLines) {
  const auto c = read("# header\n1 2 3 4\n\n  5.5\t6e1 -7 8 # trailing comment\n");
  EXPECT_TRUE(c.error.empty());
  ASSERT_EQ(c.view1.size(), 2u);
  EXPECT_EQ(c.view1[1], cv::Point2d(5.5, 60));
  EXPECT_EQ(c.view2[1], cv::Point2d(-7, 8));
}

TEST(CorrespondenceIo, NamesTheBadLine) {
  auto c = read("1 2 3 4\n1 2 3\n");
  EXPECT_EQ(c.error_line, 2);
  EXPECT_NE(c.error.find("line 2"), std::string::npos);
  EXPECT_NE(c.error.find("4 numbers"), std::string::npos);
  c = read("1 2 3 4\n1 2 3 4\n1 nan 3 4\n");
  EXPECT_EQ(c.error_line, 3);
  EXPECT_NE(c.error.find("'nan'"), std::string::npos);
  c = read("1 2 3 x\n");
  EXPECT_EQ(c.error_line, 1);
  c = read("1 2 3 4 5\n");
  EXPECT_EQ(c.error_line, 1);
  c = read("1 2 3 1e999\n");  // overflows to infinity
  EXPECT_EQ(c.error_line, 1);
  c = read("1 2 3 4abc\n");
  EXPECT_EQ(c.error_line, 1);
}

TEST(CorrespondenceIo, EmptyInputIsNoPoints) {
  const auto c = read("");
  EXPECT_TRUE(c.error.empty());
  EXPECT_TRUE(c.view1.empty());
}
