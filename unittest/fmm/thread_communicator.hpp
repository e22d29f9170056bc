// An in-process gcfmm::Communicator for P "ranks" that are std::threads (tests and the
// distributed benchmark): shared slots plus a reusable barrier (mutex + condition variable;
// C++17 has no std::barrier). Every collective is: write my slot, barrier, read all slots,
// barrier (so that no rank overwrites a slot another is still reading).
#ifndef GCFMM_THREAD_COMMUNICATOR_HPP
#define GCFMM_THREAD_COMMUNICATOR_HPP

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdint>
#include <cstdlib>
#include <condition_variable>
#include <cstddef>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

#include "fmm_test_util.hpp"
#include "gcfmm/communicator.hpp"

namespace gcfmm_test {

//! What the ranks of one group share.
class ThreadGroup {
 public:
  explicit ThreadGroup(int size) : size_(size), doubles_(size), bytes_(size) {}
  int size() const { return size_; }

  //! blocks until all ranks have arrived (reusable: a generation counter); a rank that waits
  //! longer than kHangSeconds means the ranks made different collective calls (a hang):
  //! abort with a message instead of hanging the test run
  void barrier() {
    std::unique_lock<std::mutex> lock(mutex_);
    const long gen = generation_;
    if (++arrived_ == size_) {
      arrived_ = 0;
      ++generation_;
      cv_.notify_all();
    } else if (!cv_.wait_for(lock, std::chrono::seconds(kHangSeconds), [&] { return generation_ != gen; })) {
      std::fprintf(stderr, "ThreadGroup: ranks did not meet in a collective for %d s (hang)\n", kHangSeconds);
      std::abort();
    }
  }
  static constexpr int kHangSeconds = 30;
  std::vector<std::vector<double>> doubles_;                      // one slot per rank
  std::vector<const std::vector<std::vector<unsigned char>> *> bytes_;  // each rank's send buffers

 private:
  int size_;
  std::mutex mutex_;
  std::condition_variable cv_;
  int arrived_ = 0;
  long generation_ = 0;
};

class ThreadCommunicator final : public gcfmm::Communicator {
 public:
  ThreadCommunicator(ThreadGroup &group, int rank) : g_(group), rank_(rank) {}
  int rank() const override { return rank_; }
  int size() const override { return g_.size(); }
  std::size_t calls() const { return calls_; }  //!< collective calls made by this rank

  void allreduce_sum(double *data, std::size_t count) override {
    reduce(data, count, [](double a, double b) { return a + b; });
  }
  void allreduce_max(double *data, std::size_t count) override {
    reduce(data, count, [](double a, double b) { return std::max(a, b); });
  }
  void allgather(const double *mine, std::size_t count, double *all) override {
    ++calls_;
    g_.doubles_[rank_].assign(mine, mine + count);
    g_.barrier();
    for (int r = 0; r < size(); ++r) std::copy(g_.doubles_[r].begin(), g_.doubles_[r].end(), all + r * count);
    g_.barrier();
  }
  void alltoallv(const std::vector<std::vector<unsigned char>> &send,
                 std::vector<std::vector<unsigned char>> &recv) override {
    ++calls_;
    g_.bytes_[rank_] = &send;
    g_.barrier();
    recv.assign(size(), {});
    for (int r = 0; r < size(); ++r) {
      const auto &s = *g_.bytes_[r];
      if (static_cast<std::size_t>(rank_) < s.size()) recv[r] = s[rank_];
    }
    g_.barrier();
  }

 private:
  // sum in rank order on every rank: the same result everywhere
  template <class Op>
  void reduce(double *data, std::size_t count, Op op) {
    ++calls_;
    g_.doubles_[rank_].assign(data, data + count);
    g_.barrier();
    for (std::size_t i = 0; i < count; ++i) {
      double acc = g_.doubles_[0][i];
      for (int r = 1; r < size(); ++r) acc = op(acc, g_.doubles_[r][i]);
      data[i] = acc;
    }
    g_.barrier();
  }
  ThreadGroup &g_;
  int rank_;
  std::size_t calls_ = 0;
};

//! The particles of `rank` (owner[i] == rank) and their ids (their indices in p).
inline void rank_share(const Particles &p, const std::vector<int> &owner, int rank, Particles &mine,
                       std::vector<std::int64_t> &ids) {
  mine = Particles{};
  ids.clear();
  for (std::size_t i = 0; i < p.size(); ++i)
    if (owner[i] == rank) {
      mine.x.push_back(p.x[i]);
      mine.y.push_back(p.y[i]);
      mine.z.push_back(p.z[i]);
      mine.q.push_back(p.q[i]);
      ids.push_back(static_cast<std::int64_t>(i));
    }
}

//! The rank of every particle for a px x py x pz grid of ranks over the particles' bounding
//! box (rank (ix py + iy) pz + iz); px x py x 1 is LAMMPS' `processors * * 1`.
inline std::vector<int> grid_partition(const Particles &p, int px, int py, int pz) {
  std::vector<int> rank(p.size(), 0);
  if (p.size() == 0) return rank;
  const auto [xlo, xhi] = std::minmax_element(p.x.begin(), p.x.end());
  const auto [ylo, yhi] = std::minmax_element(p.y.begin(), p.y.end());
  const auto [zlo, zhi] = std::minmax_element(p.z.begin(), p.z.end());
  auto cell = [](double v, double lo, double hi, int n) {
    return std::min(n - 1, static_cast<int>(n * (v - lo) / (hi - lo + 1e-300)));
  };
  for (std::size_t i = 0; i < p.size(); ++i)
    rank[i] = (cell(p.x[i], *xlo, *xhi, px) * py + cell(p.y[i], *ylo, *yhi, py)) * pz + cell(p.z[i], *zlo, *zhi, pz);
  return rank;
}

//! Runs f(comm) on P threads, one ThreadCommunicator each; rethrows the first rank's
//! exception (in rank order) after all threads have joined.
inline void run_ranks(int P, const std::function<void(ThreadCommunicator &)> &f) {
  ThreadGroup group(P);
  std::vector<std::exception_ptr> errors(P);
  std::vector<std::thread> threads;
  for (int r = 0; r < P; ++r)
    threads.emplace_back([&, r] {
      ThreadCommunicator comm(group, r);
      try {
        f(comm);
      } catch (...) {
        errors[r] = std::current_exception();
      }
    });
  for (auto &t : threads) t.join();
  for (auto &e : errors)
    if (e) std::rethrow_exception(e);
}

}  // namespace gcfmm_test

#endif
