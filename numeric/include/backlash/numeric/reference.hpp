// backlash/numeric/reference.hpp — Boost.Odeint integration of the segment
// ODEs, the reference every evaluator is validated against.
//
//   free mode     θL'' = −(FL/JL)·θL'
//                 θm'' = (K(θR − θL) − Fm·θm')/Jm     (output at load, eq. 39)
//                 θm'' = (K(θR − θm) − Fm·θm')/Jm     (output at motor, eq. 16)
//                 from θm = θL = θR + cot φ·θ̇m0, θm' = θL' = θ̇m0
//   contact mode  θo'' = (K(θR − θo) − (Fm+FL)·θo')/(Jm+JL)  from (θo0, θ̇o0)
//
// runge_kutta_dopri5 with dense output, abs = rel tolerance (default 1e-12),
// sampled with integrate_times.  All odeint code lives in odeint_reference.cpp.
#pragma once

#include "backlash/numeric/parametric.hpp"
#include "backlash/numeric/segment_dynamics.hpp"

#include <cstddef>
#include <functional>
#include <list>
#include <map>
#include <mutex>
#include <string>
#include <vector>

namespace backlash::numeric {

/// States at `times` (non-decreasing, ≥ 0; t = 0 is the separation point).
std::vector<FreeState> reference_free_trajectory(const Parameters& p, double dtheta_m0, const std::vector<double>& times,
                                                 double tolerance = 1e-12);
/// The same, ending at the first state for which `until` holds (that state included): the states
/// before it are the same bits as the whole run's (the gate stops at recombination, validation.cpp).
std::vector<FreeState> reference_free_trajectory(const Parameters& p, double dtheta_m0, const std::vector<double>& times,
                                                 double tolerance, const std::function<bool(const FreeState&)>& until);
std::vector<ContactState> reference_contact_trajectory(const Parameters& p, double theta_o0, double dtheta_o0,
                                                       const std::vector<double>& times, double tolerance = 1e-12);

/// One state at time t (integrates from 0 to t).
FreeState reference_free_state(const Parameters& p, double dtheta_m0, double t, double tolerance = 1e-12);
ContactState reference_contact_state(const Parameters& p, double theta_o0, double dtheta_o0, double t,
                                     double tolerance = 1e-12);

/// Any linear mode z' = A z + c (the effect modes of numeric/effects/effect_modes.hpp) from z0, at `times`.
std::vector<SmallVector> reference_linear_trajectory(const LinearSegment& segment, const SmallVector& z0,
                                                     const std::vector<double>& times, double tolerance = 1e-12);

/// Appends the bytes of `n` doubles to `key` (−0 is not 0 there; a NaN is its own bits).
void append_bits(std::string& key, const double* values, std::size_t n);

/// Results of a deterministic computation kept by the exact bits of its inputs (`key`: what
/// append_bits makes of them, with their sizes where they vary): the same inputs give the same
/// bits, so what is handed back is what computing again would give.  Thread-safe; keeps the
/// `capacity` keys used last; computes outside its lock (two threads with one key both compute,
/// to the same bits).  The gate's references use it: reference_contact_trajectory (per thread)
/// and LinearReferenceCache.
template <class Value>
class KeptByBits {
 public:
  explicit KeptByBits(std::size_t capacity) : capacity_(capacity) {}
  /// The value kept under `key`, or compute()'s, then kept.
  template <class Compute>
  Value get(std::string key, const Compute& compute) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      const auto found = kept_.find(key);
      if (found != kept_.end()) {
        ++hits_;
        order_.splice(order_.end(), order_, found->second.place);  // used last
        return found->second.value;
      }
    }
    Value value = compute();
    std::lock_guard<std::mutex> lock(mutex_);
    ++computed_;
    if (capacity_ == 0) return value;
    const auto [entry, added] = kept_.emplace(std::move(key), Entry{value, {}});
    if (added) {
      entry->second.place = order_.insert(order_.end(), entry);
      if (order_.size() > capacity_) {
        kept_.erase(order_.front());
        order_.pop_front();
      }
    }
    return value;
  }
  long hits() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return hits_;
  }
  long computed() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return computed_;
  }

 private:
  struct Entry;
  using Kept = std::map<std::string, Entry>;
  struct Entry {
    Value value;
    typename std::list<typename Kept::iterator>::iterator place;  ///< in order_
  };
  std::size_t capacity_;
  mutable std::mutex mutex_;
  Kept kept_;
  std::list<typename Kept::iterator> order_;  ///< used first … used last
  long hits_ = 0, computed_ = 0;
};

/// reference_linear_trajectory's results kept by their exact inputs — the bits of A, c, z0, the
/// times and the tolerance (and their sizes).  The effects gate of a family of models
/// (ValidatedModelFamily) meets the same mode from the same start at many model points: a mode's
/// z' = A z + c leaves out the effects it does not feel, so a candidate's range corners beside
/// another base repeat most of its flows (≈ 80 % of the discrepancy workflow's reference
/// integrations, bench/README.md "Speed at the limit").  Keeps the last `capacity` inputs
/// (≈ 6 kB each at the gate's 120 times).
class LinearReferenceCache {
 public:
  explicit LinearReferenceCache(std::size_t capacity = 2048) : kept_(capacity) {}
  /// reference_linear_trajectory(segment, z0, times, tolerance), kept or integrated.
  std::vector<SmallVector> trajectory(const LinearSegment& segment, const SmallVector& z0, const std::vector<double>& times,
                                      double tolerance);
  long hits() const { return kept_.hits(); }
  long integrations() const { return kept_.computed(); }

 private:
  KeptByBits<std::vector<SmallVector>> kept_;
};

}  // namespace backlash::numeric
