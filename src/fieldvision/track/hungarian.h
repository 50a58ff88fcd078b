// Minimum-cost assignment (the Hungarian method: Kuhn 1955, Munkres 1957), in the O(n^3)
// shortest-augmenting-path form with potentials (Jonker & Volgenant 1987). Written here because
// OpenCV has no assignment solver and the tracker and the MOT metrics need one for rectangular
// cost matrices with forbidden pairs.
#pragma once

#include <vector>

namespace fv::track {

// cost[r][c] for rows x cols (rectangular allowed); pairs with cost >= forbidden are never
// assigned. Returns for each row the assigned column or -1; the total cost is minimal over the
// assignments that use as many allowed pairs as possible.
std::vector<int> SolveAssignment(const std::vector<std::vector<double>>& cost,
                                 double forbidden = 1e9);

}  // namespace fv::track
