// The camera motion of a moving camera's TRACKS.csv, saved beside it (TRACKS.csv.motion.json) by
// `players --moving-camera` and read by `tracks draw`, so that the drawn field lines and trails
// follow the frames as in `players --draw`: the lens the frames were registered through, the
// canvas margin and each frame's homography to the first view (view_canvas.h).
#pragma once

#include <optional>
#include <string>

#include "fieldvision/camera/camera.h"
#include "fieldvision/track/view_canvas.h"

namespace fv::track {

// TRACKS.csv -> TRACKS.csv.motion.json.
std::string MotionPathFor(const std::string& tracks_path);

// Writes `canvas` to `path` through a temporary file (a failed write leaves an earlier one).
void WriteMotionFile(const ViewCanvas& canvas, const std::string& path);

// Reads a motion file. With `posed` (a camera file with a pose, for the field lines) its lens must
// be the file's (size, intrinsics, distortion) and the canvas takes its pose. Throws fv::Error
// naming the file and the key for a malformed file, and both files for another lens.
// `posed_what` names the camera in that error.
ViewCanvas ReadMotionFile(const std::string& path, const camera::Camera* posed = nullptr,
                          const std::string& posed_what = "the camera");

// The motion file beside `tracks_path` (MotionPathFor) read as ReadMotionFile does, or nullopt
// when there is none (a still camera's tracks).
std::optional<ViewCanvas> ReadMotionFor(const std::string& tracks_path,
                                        const camera::Camera* posed = nullptr,
                                        const std::string& posed_what = "the camera");

// After `players` wrote `tracks_path`: the motion file beside it written (a moving camera) or an
// earlier run's removed (a still one, canvas null). Returns a line for the user, or "".
std::string SaveMotionFor(const std::string& tracks_path, const ViewCanvas* canvas);

// After `tracks edit` wrote `tracks_path`: the motion file `from` (read first: valid) copied beside
// it byte for byte, or, with `from` empty, an earlier one there removed. Returns a line or "".
std::string CarryMotionTo(const std::string& tracks_path, const std::string& from);

}  // namespace fv::track
