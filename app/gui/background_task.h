// A computation off the UI thread whose result the editor picks up when it is ready (GL-free):
// the field hints and the fitted mirror plane. Starting a new one never waits for the last:
// a result that belongs to an older request is dropped when it arrives, and its thread is
// joined once it has finished (or at destruction).
#pragma once

#include <atomic>
#include <cstdint>
#include <exception>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <utility>
#include <vector>

namespace qs::app {

template <class T>
class BackgroundTask {
 public:
  BackgroundTask() = default;
  BackgroundTask(const BackgroundTask&) = delete;
  BackgroundTask& operator=(const BackgroundTask&) = delete;
  ~BackgroundTask() {
    for (auto& job : jobs_)
      if (job.thread.joinable()) job.thread.join();
  }

  //! Runs \p work on a new thread; its result (or the text of what it threw) is the one for
  //! \p key. An earlier request still running is left to finish and dropped.
  void start(std::uint64_t key, std::function<T()> work) {
    auto shared = std::make_shared<Shared>();
    Job job;
    job.key = key;
    job.shared = shared;
    job.thread = std::thread([shared, work = std::move(work)] {
      try {
        shared->result.emplace(work());
      } catch (const std::exception& e) {
        shared->error = e.what();
      } catch (...) {
        shared->error = "unknown error";
      }
      shared->done = true;
    });
    jobs_.push_back(std::move(job));
    key_ = key;
    requested_ = true;
  }

  //! True while the latest request has not finished.
  bool running() const {
    return requested_ && !jobs_.empty() && jobs_.back().key == key_ && !jobs_.back().shared->done;
  }
  //! The key of the latest request (meaningful once start() was called).
  std::uint64_t key() const { return key_; }
  bool requested() const { return requested_; }

  //! Joins finished threads; when the latest request has finished, moves its result into
  //! \p out (or its error into \p error, \p out untouched) and returns true, once.
  bool poll(std::optional<T>& out, std::string& error) {
    bool delivered = false;
    for (auto it = jobs_.begin(); it != jobs_.end();) {
      if (!it->shared->done) {
        ++it;
        continue;
      }
      it->thread.join();
      if (it->key == key_ && &*it == &jobs_.back()) {
        if (it->shared->result)
          out = std::move(it->shared->result);
        else
          error = it->shared->error;
        delivered = true;
      }
      it = jobs_.erase(it);
    }
    return delivered;
  }

 private:
  struct Shared {
    std::atomic<bool> done{false};
    std::optional<T> result;
    std::string error;
  };
  struct Job {
    std::uint64_t key = 0;
    std::shared_ptr<Shared> shared;
    std::thread thread;
  };
  std::vector<Job> jobs_;
  std::uint64_t key_ = 0;
  bool requested_ = false;
};

}  // namespace qs::app
