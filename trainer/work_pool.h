// The trainer's threads: a fixed set of worker threads that run the chunks
// of a loop, the calling thread included, with no thread ever waiting for
// another one to START.
//
// Why not OpenMP: an OpenMP parallel region (and Eigen's threaded matrix
// product, which synchronises its threads by spinning) ends only when every
// thread of the team has arrived. When another process holds one of the
// cores, the thread that lives there starts late or runs at half speed, and
// the whole region waits for it: with one of two cores busy, training with
// two threads ran 1.8x SLOWER than with one (docs/trainer.md, "Threads").
// Here the chunks are claimed one at a time from a shared counter: a thread
// that does not get a core simply claims fewer chunks (or none), and run()
// returns as soon as every chunk is done. The slowdown on a shared machine
// is then about the share of the CPU the trainer gets.
//
// Determinism: which thread runs which chunk varies from run to run, so the
// callers split their work into chunks that do not depend on the number of
// threads, and each chunk writes its own outputs: results are bit-identical
// for any thread count.
#ifndef HADYNET_TRAINER_WORK_POOL_H_
#define HADYNET_TRAINER_WORK_POOL_H_

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <thread>
#include <vector>

namespace hadynet::trainer {

class WorkPool {
 public:
  // `threads` >= 1 threads in all: the caller of run() and threads - 1 workers.
  explicit WorkPool(int threads);
  ~WorkPool();
  WorkPool(const WorkPool&) = delete;
  WorkPool& operator=(const WorkPool&) = delete;

  int threads() const { return static_cast<int>(workers_.size()) + 1; }

  // Calls body(i) once for every i in [0, chunks) and returns when all calls
  // have returned. The calls run on any of the pool's threads, the caller
  // included, in any order and concurrently: each must touch only its own
  // outputs, and must not throw (a worker that catches an exception ends the
  // program). Not reentrant: one run() at a time, and not from inside a body.
  template <class Body>
  void run(int chunks, const Body& body) {
    run_erased(chunks, &body, [](const void* b, int i) { (*static_cast<const Body*>(b))(i); });
  }

 private:
  using Invoke = void (*)(const void* body, int chunk);
  void run_erased(int chunks, const void* body, Invoke invoke);
  // Makes `generation` the current one and wakes the sleeping workers.
  void publish(std::uint32_t generation);
  // Claims and runs chunks of the current job until none is left.
  void work();
  void worker_loop();

  // The job: [generation:24][chunks:20][next:20]. A thread claims chunk
  // `next` by advancing `next` with a compare-and-swap, so a claim can only
  // succeed on the current job; `body_` and `invoke_` are written before the
  // job is published and read only after a successful claim.
  std::atomic<std::uint64_t> ticket_{0};
  std::atomic<int> done_{0};               // chunks of the current job finished
  std::atomic<std::uint32_t> published_{0};  // generation of the current job
  std::atomic<bool> stop_{false};
  std::mutex sleep_mutex_;             // workers with nothing to do sleep on wake_
  std::condition_variable wake_;
  const void* body_ = nullptr;
  Invoke invoke_ = nullptr;
  std::vector<std::thread> workers_;
};

// The pool the trainer's network uses (hadynet_network.cc). One thread until
// set_training_threads() is called (hadynet train --threads).
WorkPool& training_pool();
// Replaces the pool with one of `threads` threads (0: every hardware thread).
// Not while a run() is in progress.
void set_training_threads(int threads);

}  // namespace hadynet::trainer

#endif  // HADYNET_TRAINER_WORK_POOL_H_
