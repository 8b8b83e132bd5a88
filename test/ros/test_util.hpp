#pragma once

#include <ros/ros.h>

#include <chrono>
#include <condition_variable>
#include <algorithm>
#include <functional>
#include <mutex>

namespace act_color_test {

// Collects state from subscriber callbacks and lets the test wait for a condition on it with a
// deadline (no bare sleeps): callbacks call notify() after changing the state under mutex().
class Waiter {
 public:
  std::mutex& mutex() { return mutex_; }
  void notify() { cv_.notify_all(); }
  // True when `done` became true before `timeout_s` (wall time) passed; `done` runs under mutex().
  bool waitFor(double timeout_s, const std::function<bool()>& done) {
    std::unique_lock<std::mutex> lock(mutex_);
    const auto deadline = std::chrono::steady_clock::now() +
                          std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                              std::chrono::duration<double>(timeout_s));
    // Re-checks at least every 100 ms as well, for conditions that depend on time.
    while (!done()) {
      if (std::chrono::steady_clock::now() >= deadline) return false;
      const std::chrono::steady_clock::time_point next =
          std::chrono::steady_clock::now() + std::chrono::milliseconds(100);
      cv_.wait_until(lock, std::min(deadline, next));
    }
    return true;
  }

 private:
  std::mutex mutex_;
  std::condition_variable cv_;
};

}  // namespace act_color_test
