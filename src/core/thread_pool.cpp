#include "core/thread_pool.h"

#include <algorithm>
#include <condition_variable>
#include <cstddef>
#include <deque>
#include <mutex>
#include <system_error>
#include <thread>
#include <vector>

namespace qem::core {

namespace {

class ThreadPool {
 public:
  void run(unsigned helpers, const std::function<void(unsigned)>& work) {
    Job job{&work, helpers};
    {
      std::lock_guard<std::mutex> lock(mutex_);
      grow(helpers);
      if (!threads_.empty()) {
        open_.push_back(&job);
        wake_.notify_all();
      }
    }
    work(0);
    std::unique_lock<std::mutex> lock(mutex_);
    // No helper joins from here on; those that did are waited for.
    open_.erase(std::remove(open_.begin(), open_.end(), &job), open_.end());
    done_.wait(lock, [&] { return job.running == 0; });
  }

 private:
  struct Job {
    const std::function<void(unsigned)>* work;
    unsigned wanted;       // helpers it may have
    unsigned joined = 0;   // helpers that took a slot
    unsigned running = 0;  // of those, the ones not yet returned
  };

  // Enough threads for `helpers` to run at once (as many as can be had). Under mutex_.
  void grow(unsigned helpers) {
    while (threads_.size() < helpers) {
      try {
        threads_.emplace_back([this] { serve(); });
      } catch (const std::system_error&) {
        return;  // the threads there (or the caller alone) do the work
      }
    }
  }

  void serve() {
    std::unique_lock<std::mutex> lock(mutex_);
    for (;;) {
      wake_.wait(lock, [&] { return !open_.empty(); });
      Job* job = open_.front();
      const unsigned slot = ++job->joined;
      ++job->running;
      if (job->joined == job->wanted) open_.pop_front();
      lock.unlock();
      (*job->work)(slot);
      lock.lock();
      if (--job->running == 0) done_.notify_all();
    }
  }

  std::mutex mutex_;
  std::condition_variable wake_, done_;
  std::deque<Job*> open_;  // jobs that still take helpers, oldest first
  std::vector<std::thread> threads_;
};

}  // namespace

void run_with_helpers(unsigned helpers, const std::function<void(unsigned)>& work) {
  if (helpers == 0) {
    work(0);
    return;
  }
  // Never destroyed: its threads wait for work until the process ends, and a static destructor
  // would have to stop them while a detached caller might still use them.
  static ThreadPool* const pool = new ThreadPool;
  pool->run(helpers, work);
}

}  // namespace qem::core
