// What a camera stage sends to the fusion stage: plain, timestamped data (camera index, frame,
// time_s and the ball candidates in that camera's pixels), serialisable to one line of JSON so
// that camera stages can later run in other processes or on other machines (JSON Lines).
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "fieldvision/recon/triangulation.h"

namespace fv::pipeline {

struct CameraMessage {
  int camera = 0;                                  // index of the camera in the rig
  long long frame = 0;                             // frame number in that camera's video, from 0
  double time_s = 0.0;                             // capture time of the frame
  std::vector<recon::BallObservation> candidates;  // best first

  // {"camera":0,"frame":12,"time_s":0.2,"candidates":[{"u":..,"v":..,"r":..,"sigma":..,
  // "score":..[,"weak":true]}]} on one line; doubles round-trip exactly.
  std::string ToJsonLine() const;
  // Throws fv::Error naming `context` and the bad key (missing, wrong type, not finite).
  static CameraMessage FromJsonLine(const std::string& line,
                                    const std::string& context = "message");
};

// The candidates as a JSON array ([{"u":..,"v":..,"r":..,"sigma":..,"score":..[,"weak":true]}])
// and back; the reader throws fv::Error naming `context` and the bad key.
nlohmann::json CandidatesToJson(const std::vector<recon::BallObservation>& candidates);
std::vector<recon::BallObservation> CandidatesFromJson(const nlohmann::json& j,
                                                       const std::string& context);

}  // namespace fv::pipeline
