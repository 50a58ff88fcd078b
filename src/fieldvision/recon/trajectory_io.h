// Flights as JSON (FLIGHTS.json, CONTRACT.md); ball tracks on disk come from ball_csv.h.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "fieldvision/recon/ball_csv.h"
#include "fieldvision/recon/trajectory.h"

namespace fv::recon {

// The contract's flight fields plus events, seen span, speed, flight time, both fits and the
// seed's method.
nlohmann::json FlightToJson(const Flight& f);
// With options: per flight that lands, the velocity and spin after the bounce that the bounce
// model (options->bounce) predicts; per bounce seen on both sides, the measured restitution,
// friction and spin change.
nlohmann::json FlightsToJson(const TrajectoryResult& result,
                             const TrajectoryOptions* options = nullptr);

}  // namespace fv::recon
