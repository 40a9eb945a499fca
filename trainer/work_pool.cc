#include "trainer/work_pool.h"

#include <algorithm>
#include <cstdio>
#include <exception>
#include <memory>
#include <stdexcept>

namespace hadynet::trainer {

namespace {

constexpr int kFieldBits = 20;
constexpr std::uint64_t kFieldMask = (std::uint64_t{1} << kFieldBits) - 1;
constexpr std::uint32_t kGenerationMask = (std::uint32_t{1} << 24) - 1;

constexpr std::uint64_t pack(std::uint32_t generation, int chunks, int next) {
  return (std::uint64_t{generation} << (2 * kFieldBits)) | (static_cast<std::uint64_t>(chunks) << kFieldBits) |
         static_cast<std::uint64_t>(next);
}
constexpr int chunks_of(std::uint64_t ticket) { return static_cast<int>((ticket >> kFieldBits) & kFieldMask); }
constexpr int next_of(std::uint64_t ticket) { return static_cast<int>(ticket & kFieldMask); }

// A worker that finds no job yields its core this many times (a few
// milliseconds) before it sleeps: jobs come six per training step with
// serial work between them, and waking a sleeping thread for each cost 4 %
// of an epoch with 2000 yields and 8 % with 200 (bench/train_shared_core.sh,
// idle machine). A yield gives the core away when another process wants it,
// so the spinning costs a shared machine nothing.
constexpr int kYieldsBeforeSleep = 20000;

}  // namespace

WorkPool::WorkPool(int threads) {
  if (threads < 1) throw std::invalid_argument("WorkPool: threads must be >= 1");
  workers_.reserve(static_cast<std::size_t>(threads - 1));
  for (int i = 1; i < threads; ++i) workers_.emplace_back([this] { worker_loop(); });
}

WorkPool::~WorkPool() {
  stop_.store(true, std::memory_order_release);
  publish((published_.load(std::memory_order_relaxed) + 1) & kGenerationMask);
  for (std::thread& t : workers_) t.join();
}

void WorkPool::run_erased(int chunks, const void* body, Invoke invoke) {
  if (chunks <= 0) return;
  if (static_cast<std::uint64_t>(chunks) > kFieldMask) throw std::invalid_argument("WorkPool: too many chunks");
  if (workers_.empty() || chunks == 1) {
    for (int i = 0; i < chunks; ++i) invoke(body, i);
    return;
  }
  body_ = body;
  invoke_ = invoke;
  done_.store(0, std::memory_order_relaxed);
  const std::uint32_t generation = (published_.load(std::memory_order_relaxed) + 1) & kGenerationMask;
  ticket_.store(pack(generation, chunks, 0), std::memory_order_release);
  publish(generation);
  work();
  // Chunks other threads claimed and are still running.
  while (done_.load(std::memory_order_acquire) < chunks) std::this_thread::yield();
}

void WorkPool::publish(std::uint32_t generation) {
  {
    // Under the mutex: a worker between its check of `published_` and its
    // sleep holds it, so it cannot miss this change.
    std::lock_guard<std::mutex> lock(sleep_mutex_);
    published_.store(generation, std::memory_order_release);
  }
  wake_.notify_all();
}

void WorkPool::work() {
  std::uint64_t ticket = ticket_.load(std::memory_order_acquire);
  while (next_of(ticket) < chunks_of(ticket)) {
    // A successful exchange claims chunk next_of(ticket) of the CURRENT job
    // (a stale ticket of an earlier job differs from the current one).
    if (ticket_.compare_exchange_weak(ticket, ticket + 1, std::memory_order_acq_rel, std::memory_order_acquire)) {
      invoke_(body_, next_of(ticket));
      done_.fetch_add(1, std::memory_order_release);
      ticket = ticket_.load(std::memory_order_acquire);
    }
  }
}

void WorkPool::worker_loop() {
  std::uint32_t seen = published_.load(std::memory_order_acquire);
  while (true) {
    int yields = 0;
    std::uint32_t now;
    // (stop_ is checked too: a worker that starts after the pool's last
    // generation was published would otherwise wait for a change forever.)
    while ((now = published_.load(std::memory_order_acquire)) == seen && !stop_.load(std::memory_order_acquire)) {
      if (yields < kYieldsBeforeSleep) {
        ++yields;
        std::this_thread::yield();
      } else {
        std::unique_lock<std::mutex> lock(sleep_mutex_);
        wake_.wait(lock, [&] {
          return published_.load(std::memory_order_acquire) != seen || stop_.load(std::memory_order_acquire);
        });
      }
    }
    seen = now;
    if (stop_.load(std::memory_order_acquire)) return;
    try {
      work();
    } catch (...) {
      std::fputs("hadynet: a training thread failed\n", stderr);
      std::terminate();
    }
  }
}

namespace {
std::unique_ptr<WorkPool>& pool_slot() {
  static std::unique_ptr<WorkPool> pool = std::make_unique<WorkPool>(1);
  return pool;
}
}  // namespace

WorkPool& training_pool() { return *pool_slot(); }

void set_training_threads(int threads) {
  if (threads <= 0) threads = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  if (training_pool().threads() == threads) return;
  pool_slot() = std::make_unique<WorkPool>(threads);
}

}  // namespace hadynet::trainer
