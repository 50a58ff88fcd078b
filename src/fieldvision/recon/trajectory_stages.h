// AnalyzeTrajectory's last stages (trajectory.cc), declared here for their tests: the contacts
// between fitted arcs, each flight's end points, bounce points and the outliers of each flight.
#pragma once

#include <vector>

#include "fieldvision/recon/trajectory.h"

namespace fv::recon::detail {

// Events between consecutive pieces that are both fitted (piece_of_flight: each flight's piece):
// bounce (low, descending then rising) or hit, with the contact time where the two arcs meet. A
// bounce whose arcs do not meet, cross the ground a sample interval (the track's median) or more
// apart and leave samples of the track between them off both hid a hop: fitted from the landing
// through those samples, it gives a bounce and then a hit where it meets the next arc, or, when
// it does not meet it, two ground contacts (origin and landing from each arc's own crossing of
// the ground level), as next to a hop too short to fit.
void ResolveContacts(const std::vector<BallSample>& track, const std::vector<int>& piece_of_flight,
                     const TrajectoryOptions& options, double noise_m, std::vector<Flight>* flights,
                     std::vector<TrackBreak>* breaks);
// Origin, landing, apex and launch velocity of a flight from its model and events; a ground
// contact lies within the contact-time bounds [lo_s, hi_s] of its piece, and an arc still in the
// air at its bound began or ended in the air there (a hit; the landing then extrapolated).
void PlaceEndpoints(const TrajectoryOptions& options, double lo_s, double hi_s, Flight* f);
// A bounce is one point on the ground: the landing of the arc before and the origin of the arc
// after, weighted by the inverse extrapolation variance of each (leverage of the contact time in
// each arc's gravity fit).
void MergeBounces(const std::vector<BallSample>& track, const TrajectoryOptions& options,
                  std::vector<Flight>* flights);
// Outliers inside a flight's seen span belong to it (for the pictures); the track in time order.
void AttachOutliers(const std::vector<BallSample>& track, const std::vector<bool>& outlier,
                    Flight* f);

}  // namespace fv::recon::detail
