// `fieldvision tracks edit`: fix identities in TRACKS.csv by hand (merge, rename, name, team,
// drop) from a small JSON file, before `stats` (track/edits.h); `tracks draw`: see the result on
// the video (track/overlay.h).
#include <algorithm>
#include <filesystem>
#include <iostream>
#include <limits>
#include <optional>

#include <fmt/format.h>

#include "fieldvision/app/command.h"
#include "fieldvision/app/input_checks.h"
#include "fieldvision/camera/camera_io.h"
#include "fieldvision/field/field.h"
#include "fieldvision/io/video_source.h"
#include "fieldvision/io/video_writer.h"
#include "fieldvision/track/edits.h"
#include "fieldvision/track/mot.h"
#include "fieldvision/track/motion_file.h"
#include "fieldvision/track/overlay.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/output_path.h"

namespace fv::app {
namespace {

struct TracksEditCli {
  std::string tracks, edits, out, roster_in;
};

// The rows of --tracks: at least one, no player twice in a frame.
std::vector<track::TrackRow> ReadTracks(const std::string& path) {
  auto rows = track::ReadTracksCsv(path);
  FV_REQUIRE(!rows.empty(), "tracks file '{}' has no rows (empty, or not a TRACKS.csv)", path);
  CheckOneRowPerPlayerFrame(rows, path);
  return rows;
}

void RunTracksEdit(const TracksEditCli& c) {
  const auto rows = ReadTracks(c.tracks);
  const track::TrackEdits edits = track::ReadTrackEdits(c.edits);
  FV_REQUIRE(!edits.edits.empty(), "edits file '{}' has no edits: nothing to do", c.edits);
  std::string roster_in = c.roster_in;
  if (roster_in.empty() && std::filesystem::exists(track::RosterPathFor(c.tracks))) {
    roster_in = track::RosterPathFor(c.tracks);
  }
  // Neither the tracks nor the teams file beside them may overwrite an input.
  const std::vector<std::string> inputs = {c.tracks, c.edits, roster_in};
  util::CheckOutputPath(c.out, inputs);
  util::CheckOutputPath(track::RosterPathFor(c.out), inputs, "--out's teams file");
  const std::string motion_in = track::MotionPathFor(c.tracks);
  util::CheckOutputPath(track::MotionPathFor(c.out), {c.tracks, c.edits, roster_in, motion_in},
                        "--out's camera motion file");
  util::ResolveOutputPath(c.out);  // not a device, a folder or in a missing folder
  // A moving camera's motion goes with its tracks (tracks draw reads it); checked before writing.
  const bool has_motion = track::ReadMotionFor(c.tracks).has_value();
  const track::Roster roster = roster_in.empty() ? track::Roster{} : track::ReadRoster(roster_in);
  const track::EditResult r = track::ApplyTrackEdits(rows, roster, edits);
  track::WriteTracksCsv(r.rows, c.out);
  std::cout << r.Summary() << "\nwrote " << c.out << "\n";
  const std::string roster_done = track::SaveRosterFor(c.out, r.roster);
  if (!roster_done.empty()) std::cout << roster_done << "\n";
  const std::string motion_done = track::CarryMotionTo(c.out, has_motion ? motion_in : "");
  if (!motion_done.empty()) std::cout << motion_done << "\n";
}

struct TracksDrawCli {
  std::string tracks, video, out, camera, field, roster_in;
  track::OverlayOptions overlay;
  double fps = 0;
  int max_frames = 0;
};

// The boxes that lie wholly outside frames of `size`.
size_t BoxesOutside(const std::vector<track::TrackRow>& rows, cv::Size size) {
  const cv::Rect2d frame(0, 0, size.width, size.height);
  return static_cast<size_t>(std::count_if(
      rows.begin(), rows.end(), [&](const auto& r) { return (r.box & frame).area() <= 0; }));
}

// Which of the drawn frames the tracks cover; warnings where tracks drawn on a video they were not
// made from run past its end or lie beside its frames.
void ReportTracksOnVideo(const std::vector<track::TrackRow>& rows, const track::DrawVideoResult& d,
                         const std::string& video, int max_frames) {
  int first_frame = std::numeric_limits<int>::max(), last_frame = 0;
  for (const auto& r : rows) {
    first_frame = std::min(first_frame, r.frame);
    last_frame = std::max(last_frame, r.frame);
  }
  const size_t outside = BoxesOutside(rows, d.frame_size);
  if (last_frame <= d.frames && (first_frame > 1 || last_frame < d.frames)) {
    std::cout << fmt::format(
        "the tracks cover frames {}-{} of the {} drawn; the others have no "
        "boxes\n",
        first_frame, last_frame, d.frames);
  }
  if (max_frames <= 0 && last_frame > d.frames) {
    std::cerr << fmt::format(
        "warning: the tracks run to frame {} but video '{}' has {} frames: is it the video they "
        "were tracked on?\n",
        last_frame, video, d.frames);
  }
  if (outside > 0) {
    std::cerr << fmt::format(
        "warning: {} of {} boxes lie outside the {}x{} frames of video '{}': is it the video they "
        "were tracked on?\n",
        outside, rows.size(), d.frame_size.width, d.frame_size.height, video);
  }
}

// Tracks of which most boxes lie beside the video's frames were made on another video: an error
// before anything is written (a few beside them are warned of after drawing).
void CheckTracksFitVideo(const std::vector<track::TrackRow>& rows, const io::VideoSource& video,
                         const std::string& tracks) {
  const size_t outside = BoxesOutside(rows, cv::Size(video.width(), video.height()));
  FV_REQUIRE(outside * 2 <= rows.size(),
             "tracks draw: {} of the {} boxes of '{}' lie outside the {}x{} frames of video '{}' "
             "(tracks of another video?); nothing written",
             outside, rows.size(), tracks, video.width(), video.height(), video.spec());
}

// The video with the (edited) tracks drawn: names from the roster, team colours.
void RunTracksDraw(const TracksDrawCli& c) {
  std::string roster_in = c.roster_in;
  if (roster_in.empty() && std::filesystem::exists(track::RosterPathFor(c.tracks))) {
    roster_in = track::RosterPathFor(c.tracks);
  }
  io::CheckVideoOutput(c.out, {c.tracks, c.video, c.camera, c.field, roster_in}, "--out");
  const auto rows = ReadTracks(c.tracks);
  const track::Roster roster = roster_in.empty() ? track::Roster{} : track::ReadRoster(roster_in);
  const std::unique_ptr<io::VideoSource> probe = io::VideoSource::Open(c.video);
  CheckTracksFitVideo(rows, *probe, c.tracks);
  std::optional<camera::Camera> camera;
  if (!c.camera.empty()) {
    camera = camera::ReadCameraYaml(c.camera);
    // Field lines drawn with a camera of another size would be wrong everywhere.
    const std::string note = probe->FitCamera(*camera, c.camera);
    if (!note.empty()) std::cout << note << "\n";
  }
  std::optional<field::FieldModel> field;
  // Lines are drawn through a posed camera only: a field without one would be left out silently.
  FV_REQUIRE(c.field.empty() || (camera && camera->has_pose),
             "--field draws the field's lines through a posed camera: give --camera CAM.yaml "
             "with a pose");
  if (!c.field.empty()) field = field::LoadField(c.field);
  track::TrackOverlay overlay(rows, roster.team_of, roster.name_of, camera ? &*camera : nullptr,
                              field ? &*field : nullptr, c.overlay);
  // A moving camera's tracks: the lines and trails follow its frames as players --draw drew them.
  if (const auto canvas =
          track::ReadMotionFor(c.tracks, camera && camera->has_pose ? &*camera : nullptr,
                               fmt::format("camera file '{}'", c.camera))) {
    overlay.SetCameraMotion(*canvas);
    std::cout << "camera motion from " << track::MotionPathFor(c.tracks) << " (" << canvas->frames()
              << " frames)\n";
  }
  const track::DrawVideoResult d =
      track::DrawTracksVideo(c.video, c.out, overlay, c.fps, c.max_frames);
  std::cout << d.Summary() << "\n";
  ReportTracksOnVideo(rows, d, c.video, c.max_frames);
}

void Setup(CLI::App& app, int& exit_code) {
  CLI::App* group = CommandGroup(app, "tracks");
  auto c = std::make_shared<TracksEditCli>();
  CLI::App* cmd = group->add_subcommand(
      "edit",
      "Apply identity edits to TRACKS.csv (merge ids, rename to shirt numbers, names, teams, drop "
      "ids); run stats on the result");
  cmd->add_option("--tracks", c->tracks, "TRACKS.csv from `fieldvision players`")->required();
  cmd->add_option("--edits", c->edits,
                  "JSON array of edits, applied in order: {\"merge\": [3, 17]}, "
                  "{\"rename\": {\"3\": 10}}, {\"name\": {\"10\": \"Anna\"}}, "
                  "{\"team\": {\"10\": 0}}, {\"drop\": [5]}")
      ->required();
  cmd->add_option("--out", c->out,
                  "Edited TRACKS.csv (teams and names go to OUT.teams.csv beside it)")
      ->required();
  cmd->add_option("--roster", c->roster_in,
                  "id,team[,name] CSV to start from (default: TRACKS.csv.teams.csv if present)");
  cmd->callback([c] { RunTracksEdit(*c); });

  auto d = std::make_shared<TracksDrawCli>();
  CLI::App* draw = group->add_subcommand(
      "draw",
      "Draw TRACKS.csv on its video (boxes, ids or roster names, team colours, trails, field "
      "lines with a posed camera and --field): H.264 .mp4, or MJPG .avi without the encoder");
  draw->add_option("--tracks", d->tracks, "TRACKS.csv (e.g. after tracks edit)")->required();
  draw->add_option("--video", d->video, "The video the tracks come from")->required();
  draw->add_option("--out", d->out, "Output video (.mp4)")->required();
  draw->add_option("--camera", d->camera, "Camera file with a pose (for the field lines)");
  draw->add_option("--field", d->field, "Field (built-in name or JSON) whose lines are drawn");
  draw->add_option("--roster", d->roster_in,
                   "id,team[,name] CSV (default: TRACKS.csv.teams.csv if present)");
  draw->add_option("--fps", d->fps, "Frame rate of the output (default: the video's)")
      ->check(FiniteRange(0.01, 10000));
  draw->add_option("--max-frames", d->max_frames, "Draw at most this many frames (0: all)")
      ->check(FiniteRange(0, 1e9));
  draw->add_flag("!--no-legend", d->overlay.legend,
                 "Leave out the legend in the bottom-left corner (teams, boxes, trails, lines)");
  draw->callback([d] { RunTracksDraw(*d); });
}

FV_REGISTER_COMMAND(72, "tracks edit", Setup);

}  // namespace
}  // namespace fv::app
