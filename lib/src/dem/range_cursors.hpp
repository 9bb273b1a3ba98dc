#pragma once
// Work shared out in one contiguous range per thread, with the ranges' leftovers taken by
// whichever thread is free.
//
// A static split keeps each thread on the data it wrote the step before (its core's cache; two
// threads handed work dynamically were measured no faster than one, docs/dem.md, session 27).
// But this VM's two cores run at uneven speeds from one moment to the next: with a static split
// the faster thread waited at the stage's barrier for up to a fifth of the step (session 28).
// Here each thread first works through its own range from the front, then helps with the other
// ranges. Every item is claimed by one atomic increment of its range's cursor, so it is done
// exactly once, by whichever thread claimed it: the work done must not depend on which thread
// does it (results keep their bits for any thread count and any timing).
#include <algorithm>
#include <atomic>
#include <memory>

namespace clumpkit::dem {

class RangeCursors {
 public:
  // The ranges are set before any thread runs (outside the parallel region, or inside it
  // before a barrier). run() visits every range, so all items are done even when the region
  // has fewer threads than ranges.
  /// Items [0, n) in `threads` contiguous ranges of about equal size.
  void split_evenly(int n, int threads) {
    resize(threads);
    for (int t = 0; t < n_; ++t)
      set_range(t, static_cast<int>(static_cast<long long>(n) * t / n_),
                static_cast<int>(static_cast<long long>(n) * (t + 1) / n_));
  }
  /// Makes room for n threads' ranges; then set_range for each.
  void resize(int n) {
    if (n != n_) {
      cursors_ = std::make_unique<Cursor[]>(std::max(n, 0));
      n_ = std::max(n, 0);
    }
  }
  void set_range(int t, int begin, int end) {
    cursors_[t].next.store(begin, std::memory_order_relaxed);
    cursors_[t].end = end;
  }
  /// Calls f(begin, end) on pieces of at most `chunk` items: thread t's own range first, then
  /// what is left of the others' (t + 1, t + 2, ...). Returns when no range has items left.
  template <class F>
  void run(int t, int chunk, F&& f) {
    for (int u = 0; u < n_; ++u) {
      Cursor& c = cursors_[(t + u) % n_];
      for (;;) {
        const int a = c.next.fetch_add(chunk, std::memory_order_relaxed);
        if (a >= c.end) break;
        f(a, std::min(a + chunk, c.end));
      }
    }
  }

 private:
  // One cache line per cursor: the owner's increments do not disturb the other threads'.
  struct alignas(64) Cursor {
    std::atomic<int> next{0};
    int end = 0;
  };
  std::unique_ptr<Cursor[]> cursors_;
  int n_ = 0;
};

}  // namespace clumpkit::dem
