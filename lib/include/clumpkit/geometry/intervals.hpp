#pragma once
/// 1-D interval sets along a ray: the building block of ray-sampled volume integrals.
#include <vector>

namespace clumpkit {

struct Interval {
  double t0, t1;  ///< t0 < t1, ray parameter (metres along a unit direction)
};

/// Sorted, pairwise disjoint intervals.
using IntervalList = std::vector<Interval>;

/// Sorts and merges overlapping or touching intervals in place (union of the set).
void merge_intervals(IntervalList& list);

/// Symmetric difference (a XOR b) of two normalised lists.
IntervalList xor_intervals(const IntervalList& a, const IntervalList& b);

/// Intersection of two normalised lists.
IntervalList intersect_intervals(const IntervalList& a, const IntervalList& b);

/// Total length of a normalised list.
double total_length(const IntervalList& list);

}  // namespace clumpkit
