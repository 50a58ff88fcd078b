// The stages of RunTrajectory (trajectory_run.h), for tests.
#pragma once

#include <ostream>
#include <string>

#include <nlohmann/json.hpp>

#include "fieldvision/field/field.h"
#include "fieldvision/recon/trajectory_run.h"

namespace fv::recon {

// The analysis options for a track: the job's ball, mass and slack, or the defaults of the
// track's layout ("tt3d": table tennis, else football); says on `log` what it assumed.
TrajectoryOptions TrajectoryOptionsFor(const TrajectoryJob& job, const std::string& layout,
                                       std::ostream& log);

// FLIGHTS.json: the contract's array, each flight with its landing prediction (from
// `predict_fraction` of the flight) and the calls made in it.
nlohmann::json FlightsJson(const TrajectoryJobResult& out, double predict_fraction);

// Writes --out, --report, --smoothed and --images (each through a temporary file) and lists the
// pictures in out.images.
void WriteTrajectoryOutputs(const TrajectoryJob& job, const nlohmann::json& flights,
                            const field::FieldModel* field, TrajectoryJobResult& out);

}  // namespace fv::recon
