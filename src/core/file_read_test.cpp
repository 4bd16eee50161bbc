#include "core/file_read.hpp"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "core/error.hpp"

namespace panoptes {
namespace {

std::string message_of(const std::string& path, std::uint64_t max = 1 << 20) {
  try {
    read_regular_file(path, max, "camera file");
  } catch (const FileError& e) {
    return e.what();
  }
  return "";
}

TEST(FileRead, ReadsARegularFile) {
  const auto p = std::filesystem::temp_directory_path() / ("panoptes_file_read_" + std::to_string(::getpid()));
  std::ofstream(p) << "hello";
  EXPECT_EQ(read_regular_file(p.string(), 100), "hello");
  EXPECT_NE(message_of(p.string(), 4).find("camera file of 5 bytes is larger than the limit of 4 bytes"), std::string::npos);
  std::filesystem::remove(p);
}

TEST(FileRead, RefusesDevicesFifosAndDirectoriesWithoutBlocking) {
  EXPECT_NE(message_of("/dev/zero").find("is a character device; expected a regular camera file"), std::string::npos);
  EXPECT_NE(message_of("/tmp").find("is a directory"), std::string::npos);
  const auto fifo = std::filesystem::temp_directory_path() / ("panoptes_fifo_" + std::to_string(::getpid()));
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  EXPECT_NE(message_of(fifo.string()).find("is a FIFO"), std::string::npos);  // no writer: would block without O_NONBLOCK
  std::filesystem::remove(fifo);
  EXPECT_NE(message_of("/nonexistent/x").find("cannot open the camera file"), std::string::npos);
}

}  // namespace
}  // namespace panoptes
