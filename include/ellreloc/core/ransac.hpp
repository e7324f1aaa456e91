#pragma once
/// \file ransac.hpp
/// A generic RANSAC engine (header-only) over a duck-typed estimator, with pluggable samplers
/// (exhaustive enumeration, uniform random, PROSAC), MSAC-style scoring, an adaptive iteration
/// count with clamps, an explicit seed, hypothesis and time budgets, and statistics. An
/// optional observer sees every scored model, in sample order on the calling thread, and may
/// improve it in place before the stopping rules read it (local optimisation); the relocalizer
/// keeps its best few that way and refines them after the loop.
///
/// An Estimator provides:
///   using Model = ...;                       // a hypothesis
///   static constexpr int kSampleSize;        // minimal sample size
///   static constexpr int kMaxModels;         // models one minimal sample can produce
///   size_t numData() const;
///   int generate(const int* sample, Model* models) const;      // fills up to kMaxModels
///   double score(const Model& m, int* num_inliers) const;       // MSAC cost: lower is better
/// A sample the estimator cannot use (e.g. repeated observations) simply generates 0 models.

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdint>
#include <limits>
#include <mutex>
#include <numeric>
#include <optional>
#include <random>
#include <thread>
#include <vector>

namespace ellreloc {

struct RansacOptions {
  int min_iterations = 20;              ///< samples drawn at least (unless the sampler runs out)
  int max_iterations = 10000;           ///< samples drawn at most
  long max_hypotheses = 1000000;        ///< models scored at most
  double max_time_ms = 0.0;             ///< wall-clock budget; 0 = none
  double success_probability = 0.9999;  ///< for the adaptive iteration count
  uint64_t seed = 0;                    ///< same input + seed = same output
  /// A best model with at least `enough_inliers` inliers (a support no model can exceed, e.g.
  /// every observation explained) and a score at most `enough_score` ends the search early:
  /// `enough_extension` times as many samples again as had been drawn when it came, then stop,
  /// whatever the adaptive count asks (the extra samples look for a model of the same support
  /// that scores better). Off by default.
  int enough_inliers = std::numeric_limits<int>::max();
  double enough_score = -std::numeric_limits<double>::infinity();
  double enough_extension = 1.0;
  /// A sample drawn before (the same indices in any order) still counts as drawn, so the stopping
  /// rules read the same count, but its models are not generated and scored again. Random
  /// samplers repeat samples, most where there are few to draw from (PROSAC's first prefixes, a
  /// frame of four observations). Off by default: an estimator whose models depend on the order
  /// of the sample's indices would lose the other orders.
  bool skip_repeated_samples = false;
};

struct RansacStats {
  int iterations = 0;                                      ///< samples drawn
  long hypotheses = 0;                                     ///< models generated and scored
  int best_iteration = 0;                                  ///< the sample (1-based) that produced the returned model
  int num_inliers = 0;                                     ///< of the returned model
  double score = std::numeric_limits<double>::infinity();  ///< MSAC cost of the returned model
  double elapsed_ms = 0.0;
  bool budget_exhausted = false;   ///< stopped by max_iterations, max_hypotheses or max_time_ms
  bool sampler_exhausted = false;  ///< an exhaustive sampler enumerated everything
  int repeated_samples = 0;        ///< drawn before and skipped (skip_repeated_samples)
};

/// Draws k distinct indices of [0, n) uniformly.
class UniformSampler {
 public:
  UniformSampler(int n, int k, uint64_t seed) : n_(n), k_(k), rng_(seed) {}
  bool next(int* sample) {
    if (n_ < k_) return false;
    for (int i = 0; i < k_; ++i) {
      bool fresh;
      do {
        sample[i] = std::uniform_int_distribution<int>(0, n_ - 1)(rng_);
        fresh = std::find(sample, sample + i, sample[i]) == sample + i;
      } while (!fresh);
    }
    return true;
  }

 private:
  int n_, k_;
  std::mt19937_64 rng_;
};

/// Enumerates every k-subset of [0, n) once, in lexicographic order.
class ExhaustiveSampler {
 public:
  ExhaustiveSampler(int n, int k, uint64_t /*seed*/ = 0) : n_(n), k_(k), current_(static_cast<size_t>(k)) {
    std::iota(current_.begin(), current_.end(), 0);
    done_ = n < k || k <= 0;
  }
  bool next(int* sample) {
    if (done_) return false;
    std::copy(current_.begin(), current_.end(), sample);
    // Advance: the rightmost index that can still move, then reset the ones after it.
    int i = k_ - 1;
    while (i >= 0 && current_[i] == n_ - k_ + i) --i;
    if (i < 0) {
      done_ = true;
    } else {
      ++current_[i];
      for (int j = i + 1; j < k_; ++j) current_[j] = current_[j - 1] + 1;
    }
    return true;
  }

 private:
  int n_, k_;
  std::vector<int> current_;
  bool done_;
};

/// PROSAC (Chum & Matas, CVPR 2005): data indices are assumed sorted by decreasing quality
/// (index 0 best). Samples are drawn from a growing prefix, the newest element of the prefix
/// always included, so good data is tried first; after `growth_max` samples it is uniform.
class ProsacSampler {
 public:
  ProsacSampler(int n, int k, uint64_t seed, int growth_max = 20000)
      : n_(n), k_(k), rng_(seed), growth_max_(growth_max), subset_(k) {
    // T_n: expected number of samples from the first n among growth_max samples of all N.
    t_n_ = growth_max_;
    for (int i = 0; i < k_; ++i) t_n_ *= static_cast<double>(k_ - i) / (n_ - i);
    t_n_prime_ = 1;
  }
  bool next(int* sample) {
    if (n_ < k_) return false;
    ++t_;
    if (t_ > t_n_prime_ && subset_ < n_) {
      const double t_next = t_n_ * (subset_ + 1) / (subset_ + 1 - k_);
      t_n_prime_ += static_cast<int>(std::ceil(t_next - t_n_));
      t_n_ = t_next;
      ++subset_;
    }
    if (t_n_prime_ < t_ || subset_ >= n_ || t_ > growth_max_) {
      // Uniform over the current prefix.
      drawDistinct(sample, 0, k_, subset_);
    } else {
      // k-1 from the first subset-1, plus element subset-1.
      drawDistinct(sample, 0, k_ - 1, subset_ - 1);
      sample[k_ - 1] = subset_ - 1;
    }
    return true;
  }

 private:
  void drawDistinct(int* sample, int from, int to, int range) {
    for (int i = from; i < to; ++i) {
      bool fresh;
      do {
        sample[i] = std::uniform_int_distribution<int>(0, range - 1)(rng_);
        fresh = std::find(sample, sample + i, sample[i]) == sample + i;
      } while (!fresh);
    }
  }
  int n_, k_;
  std::mt19937_64 rng_;
  int growth_max_;
  int subset_;
  long t_ = 0;
  double t_n_ = 0;
  long t_n_prime_ = 1;
};

/// Number of samples needed to draw an all-inlier sample with the given probability.
inline int adaptiveIterations(double inlier_ratio, int sample_size, double success_probability) {
  if (inlier_ratio >= 1.0) return 0;
  if (inlier_ratio <= 0.0) return std::numeric_limits<int>::max();
  const double p_good = std::pow(inlier_ratio, sample_size);
  if (p_good <= 1e-300) return std::numeric_limits<int>::max();
  const double k = std::log(1.0 - success_probability) / std::log(1.0 - p_good);
  return k > 1e9 ? std::numeric_limits<int>::max() : static_cast<int>(std::ceil(k));
}

/// An observer that ignores every scored model.
struct IgnoreScoredModels {
  template <typename Model>
  void operator()(const Model&, double /*score*/, int /*num_inliers*/) const {}
};

namespace detail {

/// The samples drawn so far, each as its sorted indices (skip_repeated_samples): an
/// open-addressing table, so that remembering a sample costs a few operations and no allocation
/// (a search draws thousands, most of which it drops at once).
template <int K>
class DrawnSamples {
 public:
  /// True when `sample` (in any order) was not drawn before; remembers it.
  bool insert(const int* sample) {
    Key key;
    for (int i = 0; i < K; ++i) {  // insertion sort: K is a minimal sample's size, a handful
      int j = i;
      for (; j > 0 && key[j - 1] > sample[i]; --j) key[j] = key[j - 1];
      key[j] = sample[i];
    }
    if (2 * (size_ + 1) > slots_.size()) grow();
    if (!place(key, &slots_)) return false;
    ++size_;
    return true;
  }

 private:
  using Key = std::array<int, K>;
  static constexpr int kEmpty = -1;  // sample indices are never negative

  static uint64_t hash(const Key& key) {
    uint64_t h = 0x9e3779b97f4a7c15ull;
    for (int i : key) h = (h ^ static_cast<uint32_t>(i)) * 0xff51afd7ed558ccdull;
    return h ^ (h >> 29);
  }
  /// Puts `key` in `table` (a power of two long) unless it is there; false when it was.
  static bool place(const Key& key, std::vector<Key>* table) {
    const size_t mask = table->size() - 1;
    for (size_t i = hash(key) & mask;; i = (i + 1) & mask) {
      Key& slot = (*table)[i];
      if (slot[0] == kEmpty) return slot = key, true;
      if (slot == key) return false;
    }
  }
  void grow() {
    Key empty;
    empty.fill(kEmpty);
    std::vector<Key> larger(std::max<size_t>(1024, 2 * slots_.size()), empty);
    for (const Key& key : slots_)
      if (key[0] != kEmpty) place(key, &larger);
    slots_.swap(larger);
  }
  std::vector<Key> slots_;
  size_t size_ = 0;
};

/// Runs a function on `threads` threads (the calling one among them) once per call of run(),
/// and waits for all of them: a small pool for one RANSAC call's batches. A batch takes tens of
/// microseconds, about what waking a sleeping thread costs, so the threads spin briefly on an
/// atomic counter before they sleep, and the caller spins until they are done.
class BatchWorkers {
 public:
  template <typename Work>
  BatchWorkers(int threads, Work work) {
    for (int t = 1; t < threads; ++t)
      threads_.emplace_back([this, t, work] {
        int seen = 0;
        while (true) {
          for (int spins = 0; generation_.load(std::memory_order_acquire) == seen && !quit_.load(); ++spins) {
            if (spins < kSpins) {
              std::this_thread::yield();
              continue;
            }
            std::unique_lock<std::mutex> lock(mutex_);
            wake_.wait(lock, [&] { return quit_.load() || generation_.load() != seen; });
          }
          if (quit_.load()) return;
          seen = generation_.load(std::memory_order_acquire);
          work(t);
          finished_.fetch_add(1, std::memory_order_acq_rel);
        }
      });
  }
  ~BatchWorkers() {
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      quit_ = true;
    }
    wake_.notify_all();
    for (std::thread& t : threads_) t.join();
  }
  /// work(0) here and work(t) on each other thread; returns when all have returned.
  template <typename Work>
  void run(Work work) {
    finished_.store(0, std::memory_order_relaxed);
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      generation_.fetch_add(1, std::memory_order_release);
    }
    wake_.notify_all();
    work(0);
    while (finished_.load(std::memory_order_acquire) < static_cast<int>(threads_.size())) std::this_thread::yield();
  }

 private:
  static constexpr int kSpins = 2000;  // yields before sleeping: a few hundred microseconds
  std::vector<std::thread> threads_;
  std::mutex mutex_;
  std::condition_variable wake_;
  std::atomic<int> generation_{0}, finished_{0};
  std::atomic<bool> quit_{false};
};

}  // namespace detail

/// Runs RANSAC with one estimator per thread: samples are drawn in order in batches whose
/// models are generated and scored on `estimators.size()` threads (estimators[t] only on thread
/// t, so each may keep scratch state; they must give the same models and scores for a sample),
/// then taken in sample order under the serial stopping rules. The result, the statistics and
/// the observer's calls are therefore those of one estimator on one thread (unless the time
/// budget stops it); only samples drawn past the stopping point are wasted work.
/// `best` receives the best model; returns false when no model was generated.
template <typename Estimator, typename Sampler, typename Observer = IgnoreScoredModels>
bool ransacOnThreads(const std::vector<const Estimator*>& estimators, Sampler& sampler, const RansacOptions& options,
                     typename Estimator::Model* best, RansacStats* stats, Observer&& observer = Observer{}) {
  using Clock = std::chrono::steady_clock;
  using Model = typename Estimator::Model;
  struct Slot {
    int sample[Estimator::kSampleSize];
    Model models[Estimator::kMaxModels];
    double scores[Estimator::kMaxModels];
    int inliers[Estimator::kMaxModels];
    int count = 0;
    bool repeated = false;  // drawn before: generates nothing
  };
  const auto start = Clock::now();
  const int threads = std::max(1, static_cast<int>(estimators.size()));
  // One sample at a time on one thread: nothing is generated past the stopping point. On more,
  // batches large enough that waiting for each costs little next to its work (a sample takes a
  // few microseconds, and so does waking the threads); at most a batch is drawn past the stop.
  const int batch_capacity = threads == 1 ? 1 : 32 * threads;
  std::vector<Slot> batch(static_cast<size_t>(batch_capacity));
  int filled = 0, cursor = 0;
  std::atomic<int> next_slot{0};
  const auto work = [&](int t) {
    const Estimator& estimator = *estimators[static_cast<size_t>(t)];
    for (int i = next_slot++; i < filled; i = next_slot++) {
      Slot& s = batch[static_cast<size_t>(i)];
      s.count = s.repeated ? 0 : estimator.generate(s.sample, s.models);
      for (int m = 0; m < s.count; ++m) s.scores[m] = estimator.score(s.models[m], &s.inliers[m]);
    }
  };
  std::optional<detail::BatchWorkers> workers;
  if (threads > 1) workers.emplace(threads, work);
  RansacStats st;
  detail::DrawnSamples<Estimator::kSampleSize> drawn;
  const size_t n = estimators.front()->numData();
  int needed = options.max_iterations;
  int enough_stop = std::numeric_limits<int>::max();  // set once, by the first good enough best model
  bool have = false, sampler_done = false;
  while (true) {
    if (st.iterations >= options.max_iterations || st.hypotheses >= options.max_hypotheses) {
      st.budget_exhausted = true;
      break;
    }
    const int stop_at = std::max(options.min_iterations, std::min(needed, enough_stop));
    if (st.iterations >= stop_at) break;
    if (options.max_time_ms > 0.0 && (st.iterations & 7) == 0 &&
        std::chrono::duration<double, std::milli>(Clock::now() - start).count() > options.max_time_ms) {
      st.budget_exhausted = true;
      break;
    }
    if (cursor == filled) {  // the next batch: as many samples as the loop may still take
      const long room = std::min<long>({options.max_iterations - st.iterations, stop_at - st.iterations,
                                        options.max_hypotheses - st.hypotheses, batch_capacity});
      filled = cursor = 0;
      while (!sampler_done && filled < room) {
        Slot& slot = batch[static_cast<size_t>(filled)];
        if (sampler.next(slot.sample)) {
          slot.repeated = options.skip_repeated_samples && !drawn.insert(slot.sample);
          st.repeated_samples += slot.repeated;
          ++filled;
        } else {
          sampler_done = true;
        }
      }
      if (filled == 0) {
        st.sampler_exhausted = true;
        break;
      }
      next_slot = 0;
      if (workers)
        workers->run(work);
      else
        work(0);
    }
    Slot& s = batch[static_cast<size_t>(cursor++)];
    ++st.iterations;
    for (int i = 0; i < s.count; ++i) {
      ++st.hypotheses;
      observer(s.models[i], s.scores[i], s.inliers[i]);  // may improve them (on this thread, in order)
      if (s.scores[i] < st.score) {
        st.score = s.scores[i];
        st.num_inliers = s.inliers[i];
        st.best_iteration = st.iterations;
        *best = s.models[i];
        have = true;
        needed = adaptiveIterations(n ? static_cast<double>(s.inliers[i]) / n : 0.0, Estimator::kSampleSize,
                                    options.success_probability);
        if (enough_stop == std::numeric_limits<int>::max() && s.inliers[i] >= options.enough_inliers &&
            s.scores[i] <= options.enough_score)
          enough_stop = static_cast<int>(
              std::min(std::ceil(st.iterations * (1.0 + options.enough_extension)), double(options.max_iterations)));
      }
    }
  }
  st.elapsed_ms = std::chrono::duration<double, std::milli>(Clock::now() - start).count();
  if (stats) *stats = st;
  return have;
}

/// Runs RANSAC on one thread. `best` receives the best model; returns false when no model was
/// generated. `observer(model, score, num_inliers)` is called for every scored model, in order,
/// with lvalues it may change (a better model and its score and inliers: local optimisation).
template <typename Estimator, typename Sampler, typename Observer = IgnoreScoredModels>
bool ransac(const Estimator& estimator, Sampler& sampler, const RansacOptions& options, typename Estimator::Model* best,
            RansacStats* stats, Observer&& observer = Observer{}) {
  return ransacOnThreads(std::vector<const Estimator*>{&estimator}, sampler, options, best, stats,
                         std::forward<Observer>(observer));
}

}  // namespace ellreloc
