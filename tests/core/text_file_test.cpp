// The bounded, streaming file access every dyncull reader shares (core/text_file.hpp): regular files
// only, refused promptly with a reason naming the path; lines under a length and a count limit.

#include "dyncull/core/text_file.hpp"

#include "support/special_files.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace dyncull::text {
namespace {

std::vector<std::string> all_lines(LineReader& in, std::vector<LineStatus>* statuses = nullptr) {
  std::vector<std::string> out;
  std::string_view line;
  for (LineStatus s; (s = in.next(&line)) != LineStatus::End;) {
    out.emplace_back(line);
    if (statuses) statuses->push_back(s);
    if (s == LineStatus::TooManyLines || s == LineStatus::ReadError) break;
  }
  return out;
}

TEST(LineReader, ReadsLinesWithNumbersKeepingCarriageReturnsAndALastLineWithoutNewline) {
  test::ScratchDir dir;
  std::ofstream(dir / "a.txt") << "one\r\n\ntwo\nlast";
  LineReader in;
  ASSERT_TRUE(in.open(dir / "a.txt")) << in.error();
  std::string_view line;
  ASSERT_EQ(in.next(&line), LineStatus::Line);
  EXPECT_EQ(line, "one\r");
  EXPECT_EQ(in.line_number(), 1u);
  ASSERT_EQ(in.next(&line), LineStatus::Line);
  EXPECT_EQ(line, "");
  ASSERT_EQ(in.next(&line), LineStatus::Line);
  EXPECT_EQ(line, "two");
  ASSERT_EQ(in.next(&line), LineStatus::Line);
  EXPECT_EQ(line, "last");
  EXPECT_EQ(in.line_number(), 4u);
  EXPECT_EQ(in.next(&line), LineStatus::End);
  EXPECT_EQ(in.next(&line), LineStatus::End);
  EXPECT_TRUE(in.error().empty()) << in.error();
}

TEST(LineReader, LinesAcrossItsBufferAreWhole) {
  test::ScratchDir dir;
  std::string text;
  for (int i = 0; i < 20000; ++i) text += std::to_string(i) + " " + std::string(static_cast<std::size_t>(i % 13), 'x') + "\n";
  std::ofstream(dir / "big.txt") << text;
  LineReader in;
  ASSERT_TRUE(in.open(dir / "big.txt"));
  const std::vector<std::string> lines = all_lines(in);
  ASSERT_EQ(lines.size(), 20000u);
  for (int i = 0; i < 20000; i += 997)
    EXPECT_EQ(lines[static_cast<std::size_t>(i)], std::to_string(i) + " " + std::string(static_cast<std::size_t>(i % 13), 'x'));
}

TEST(LineReader, OverlongLineComesBackCutWithItsLengthAndReadingGoesOn) {
  test::ScratchDir dir;
  std::ofstream(dir / "long.txt") << "# " << std::string(300000, 'c') << "\nnext\n";
  LineReaderOptions o;
  o.max_line_chars = 100;
  LineReader in;
  ASSERT_TRUE(in.open(dir / "long.txt", o));
  std::vector<LineStatus> st;
  const std::vector<std::string> lines = all_lines(in, &st);
  ASSERT_EQ(lines.size(), 2u);
  EXPECT_EQ(st[0], LineStatus::TooLong);
  EXPECT_EQ(lines[0].size(), 100u);
  EXPECT_EQ(lines[0].substr(0, 3), "# c");
  EXPECT_EQ(st[1], LineStatus::Line);
  EXPECT_EQ(lines[1], "next");
  EXPECT_EQ(in.line_number(), 2u);
}

TEST(LineReader, StopsAfterMaxLinesWithAReason) {
  test::ScratchDir dir;
  std::ofstream(dir / "many.txt") << "a\nb\nc\nd\n";
  LineReaderOptions o;
  o.max_lines = 3;
  LineReader in;
  ASSERT_TRUE(in.open(dir / "many.txt", o));
  std::vector<LineStatus> st;
  all_lines(in, &st);
  ASSERT_EQ(st.size(), 4u);
  EXPECT_EQ(st[3], LineStatus::TooManyLines);
  EXPECT_NE(in.error().find("many.txt: more than 3 lines"), std::string::npos) << in.error();
  std::string_view line;
  EXPECT_EQ(in.next(&line), LineStatus::End);
}

TEST(LineReader, RefusesDirectoriesDevicesAndMissingFilesNamingThePath) {
  test::ScratchDir dir;
  LineReader in;
  EXPECT_FALSE(in.open(dir.str()));
  EXPECT_EQ(in.error(), dir.str() + ": is a directory, not a regular file");
  EXPECT_FALSE(in.open("/dev/zero"));
  EXPECT_EQ(in.error(), "/dev/zero: is a character device, not a regular file");
  EXPECT_FALSE(in.open(dir / "missing.txt"));
  EXPECT_EQ(in.error(), dir / "missing.txt" + ": no such file");
  std::string_view line;
  EXPECT_EQ(in.next(&line), LineStatus::End);
}

TEST(LineReader, RefusesAFifoWithoutBlocking) {
  test::ScratchDir dir;
  const std::string fifo = dir / "pipe";
  if (!test::make_fifo(fifo)) return;
  LineReader in;
  bool opened = true;
  EXPECT_TRUE(test::returns_promptly([&] { opened = in.open(fifo); }, fifo));
  EXPECT_FALSE(opened);
  EXPECT_EQ(in.error(), fifo + ": is a FIFO (named pipe), not a regular file");
}

TEST(LineReader, PathsInReasonsAreEscaped) {
  test::ScratchDir dir;
  const std::string odd = dir / "esc\x1b[31m\nname";
  LineReader in;
  EXPECT_FALSE(in.open(odd));
  EXPECT_EQ(in.error().find('\x1b'), std::string::npos) << in.error();
  EXPECT_EQ(in.error().find('\n'), std::string::npos) << in.error();
  EXPECT_NE(in.error().find("esc\\x1b[31m\\x0aname: no such file"), std::string::npos) << in.error();
}

TEST(ReadSmallFile, ReadsUpToTheLimitAndNamesTheSizeBeyondIt) {
  test::ScratchDir dir;
  std::ofstream(dir / "f.json") << std::string(1000, 'x');
  std::string text, why;
  ASSERT_TRUE(read_small_file(dir / "f.json", 1000, &text, &why)) << why;
  EXPECT_EQ(text.size(), 1000u);
  EXPECT_FALSE(read_small_file(dir / "f.json", 999, &text, &why));
  EXPECT_EQ(why, dir / "f.json" + ": 1000 bytes, over the limit of 999");
  EXPECT_TRUE(text.empty());
  EXPECT_FALSE(read_small_file(dir.str(), 999, &text, &why));
  EXPECT_EQ(why, dir.str() + ": is a directory, not a regular file");
  EXPECT_FALSE(read_small_file("/dev/zero", 999, &text, &why));
  EXPECT_EQ(why, "/dev/zero: is a character device, not a regular file");
}

// Files of the kernel's look regular and have size 0: /proc/self/pagemap streams gigabytes, /proc/kmsg
// blocks. They are refused by name, also through a link, and nothing of them is read.
TEST(FileOpeningRule, KernelFilesAreRefusedByNameAlsoThroughALink) {
  test::ScratchDir dir;
  std::filesystem::create_symlink("/proc/self/pagemap", dir / "pagemap.txt");
  std::filesystem::create_symlink("/dev/zero", dir / "zero.cfg");
  LineReader in;
  EXPECT_FALSE(in.open("/proc/self/pagemap"));
  EXPECT_EQ(in.error(), "/proc/self/pagemap: is a file of the kernel's (under /proc), not a regular file");
  EXPECT_FALSE(in.open(dir / "pagemap.txt"));
  EXPECT_NE(in.error().find("pagemap.txt: is a file of the kernel's (under /proc)"), std::string::npos) << in.error();
  EXPECT_FALSE(in.open("/sys/kernel/mm/transparent_hugepage/enabled"));
  std::string text, why;
  EXPECT_FALSE(read_small_file("/proc/self/pagemap", 1 << 20, &text, &why));
  EXPECT_NE(why.find("under /proc"), std::string::npos) << why;
  EXPECT_FALSE(read_small_file(dir / "zero.cfg", 1 << 20, &text, &why));
  EXPECT_NE(why.find("zero.cfg: is a character device"), std::string::npos) << why;
  InputFile raw;
  EXPECT_FALSE(raw.open("/proc/self/status", 1 << 20, &why));
  EXPECT_FALSE(raw.is_open());
}

TEST(FileOpeningRule, EveryEntryRefusesAFifoWithoutBlocking) {
  test::ScratchDir dir;
  const std::string fifo = dir / "pipe";
  if (!test::make_fifo(fifo)) return;
  std::string text, why;
  bool read = true;
  EXPECT_TRUE(test::returns_promptly([&] { read = read_small_file(fifo, 1000, &text, &why); }, fifo));
  EXPECT_FALSE(read);
  EXPECT_EQ(why, fifo + ": is a FIFO (named pipe), not a regular file");
  InputFile raw;
  EXPECT_TRUE(test::returns_promptly([&] { read = raw.open(fifo, 1000, &why); }, fifo));
  EXPECT_FALSE(read);
}

TEST(FileOpeningRule, EachKindHasASizeCapCheckedAtOpen) {
  test::ScratchDir dir;
  std::ofstream(dir / "list.txt") << std::string(99, 'x') << "\n";
  LineReaderOptions o;
  o.max_bytes = 99;
  LineReader in;
  EXPECT_FALSE(in.open(dir / "list.txt", o));
  EXPECT_EQ(in.error(), dir / "list.txt" + ": 100 bytes, over the limit of 99");
  o.max_bytes = 100;
  ASSERT_TRUE(in.open(dir / "list.txt", o)) << in.error();
  EXPECT_EQ(all_lines(in).size(), 1u);
  EXPECT_EQ(LineReaderOptions{}.max_bytes, kMaxListFileBytes);
  EXPECT_LT(kMaxCameraFileBytes, kMaxListFileBytes);
}

TEST(FileOpeningRule, AFileReadPastItsCapStops) {
  test::ScratchDir dir;
  std::ofstream(dir / "f.bin") << std::string(50, 'x');
  InputFile f;
  std::string why;
  ASSERT_TRUE(f.open(dir / "f.bin", 50, &why)) << why;
  std::ofstream(dir / "f.bin", std::ios::app) << std::string(50, 'y');  // grows after the open
  char buffer[200];
  long total = 0;
  long got = 0;
  while ((got = f.read(buffer, sizeof buffer)) > 0) total += got;
  EXPECT_EQ(got, -2);
  EXPECT_LE(total, 51);
}

}  // namespace
}  // namespace dyncull::text
