// Special files for reader tests: a FIFO in a scratch directory, and a guard that runs a read on a
// thread and fails the test when it does not return promptly (a reader that opens a FIFO blocks until
// a writer comes; the guard then opens the FIFO for writing so the read ends and the test can report).
#pragma once

#include <gtest/gtest.h>

#include <chrono>
#include <condition_variable>
#include <filesystem>
#include <functional>
#include <mutex>
#include <string>
#include <thread>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

namespace dyncull::test {

/// A scratch directory named after the running test, removed at destruction.
class ScratchDir {
 public:
  ScratchDir() {
    const ::testing::TestInfo* info = ::testing::UnitTest::GetInstance()->current_test_info();
    path_ = std::filesystem::temp_directory_path() /
            ("dyncull_" + std::string(info ? info->name() : "scratch") + "_" + std::to_string(::getpid()));
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ~ScratchDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;
  std::string operator/(const std::string& name) const { return (path_ / name).string(); }
  std::string str() const { return path_.string(); }

 private:
  std::filesystem::path path_;
};

/// Makes a FIFO at `path`; false (with the test failed) when mkfifo does not work here.
inline bool make_fifo(const std::string& path) {
  if (::mkfifo(path.c_str(), 0600) != 0) {
    ADD_FAILURE() << "mkfifo " << path << " failed";
    return false;
  }
  return true;
}

/// Runs `read` on a thread; true when it returned within `limit`. Otherwise the FIFO at `fifo` is
/// opened for writing and closed, which ends a read blocked on it, and false is returned.
inline bool returns_promptly(const std::function<void()>& read, const std::string& fifo,
                             std::chrono::milliseconds limit = std::chrono::milliseconds(2000)) {
  std::mutex m;
  std::condition_variable cv;
  bool done = false;
  std::thread reader([&] {
    read();
    std::lock_guard<std::mutex> lock(m);
    done = true;
    cv.notify_all();
  });
  bool prompt = false;
  {
    std::unique_lock<std::mutex> lock(m);
    prompt = cv.wait_for(lock, limit, [&] { return done; });
  }
  while (!prompt) {
    const int fd = ::open(fifo.c_str(), O_WRONLY | O_NONBLOCK);  // succeeds once the reader has it open
    if (fd >= 0) ::close(fd);
    std::unique_lock<std::mutex> lock(m);
    if (cv.wait_for(lock, std::chrono::milliseconds(50), [&] { return done; })) break;
  }
  reader.join();
  return prompt;
}

}  // namespace dyncull::test
