// The synthetic world: N calibrated cameras (fv::camera::Camera's model, so projections agree
// exactly) looking at a field with a ball, robots, people and distractors, rendered by ray casting
// with exact ground truth. Per camera the pixel rays and the static background are computed once;
// per frame only the moving objects' image boxes are ray-cast (sphere, cylinder, capsules), the
// ball shaded (Lambert with an ambient share, Phong highlight, a printed pattern turning with its
// spin) and motion-blurred, then exposure and white-balance drift, vignetting, noise and MJPG. Ball
// physics: ball_physics.h. Use: DEVELOPERS.md, "The synthetic world".
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include "fieldvision/camera/camera.h"
#include "fieldvision/field/field.h"

namespace fv::synth {

// One camera of the rig. The focal length is fx/fy when > 0, else from hfov_deg. The pose is
// rvec/tvec (OpenCV, x_cam = R x_world + t) when has_rvec_tvec, else the camera sits at
// position_m looking at look_at_m with the image's up towards +z.
struct CameraSpec {
  std::string name = "cam1";
  int width = 1280;
  int height = 960;
  double hfov_deg = 70.0;
  double fx = 0.0, fy = 0.0;       // pixels; 0: from hfov_deg
  std::vector<double> distortion;  // OpenCV order (0, 4, 5, 8, 12 or 14 values)
  Eigen::Vector3d position_m = Eigen::Vector3d(-10.5, -7.5, 4.0);
  Eigen::Vector3d look_at_m = Eigen::Vector3d::Zero();
  bool has_rvec_tvec = false;
  Eigen::Vector3d rvec = Eigen::Vector3d::Zero();
  Eigen::Vector3d tvec = Eigen::Vector3d::Zero();
};

// Ball flight physics; defaults for a size-5 football.
struct BallPhysics {
  double gravity_mps2 = 9.81;
  double drag_coefficient = 0.25;  // Cd of F = 0.5 rho Cd A v^2; 0 turns drag off
  double air_density_kgm3 = 1.2;
  double mass_kg = 0.43;
  double restitution = 0.6;           // share of the vertical speed kept at a bounce
  double bounce_friction = 0.2;       // share of the horizontal speed lost at a bounce
  double rolling_resistance = 0.04;   // rolling deceleration in units of g
  double min_bounce_speed_mps = 1.0;  // a bounce slower than this ends in rolling
  double time_step_s = 0.001;         // RK4 step
};

// A kick: at time_s the ball is at position_m (centre) and gets velocity_mps. spin_radps (world
// axis times rad/s) turns the ball's printed pattern from the kick on (the flight ignores it).
struct KickSpec {
  double time_s = 0.0;
  Eigen::Vector3d position_m = Eigen::Vector3d(0, 0, 0.11);
  Eigen::Vector3d velocity_mps = Eigen::Vector3d::Zero();
  Eigen::Vector3d spin_radps = Eigen::Vector3d::Zero();
};

// The ball and its motion: either placements (each position held for hold_frames frames, no
// motion) or kicks (ballistic flights from the first kick on; before it the ball rests at the
// first kick's position), or held_by >= 0: the ball sits in that robot's handler. enabled = false:
// no ball. pattern: "none", "print" (wavy dark bands, like the RoboCup MSL ball's print) or
// "pentagons" (the 12 pentagons of a classic football) in pattern_bgr; orientation_rvec turns it
// (placements each get a further seeded turn). specular: highlight peak in 8-bit levels
// (Phong, exponent shininess).
struct BallSpec {
  bool enabled = true;
  double diameter_m = 0.22;
  Eigen::Vector3d colour_bgr = Eigen::Vector3d(0, 110, 255);  // orange
  std::vector<Eigen::Vector3d> placements;
  int hold_frames = 1;
  std::vector<KickSpec> kicks;
  int held_by = -1;  // robot index; -1: not held
  BallPhysics physics;
  double specular = 70.0;
  double shininess = 24.0;
  std::string pattern = "none";
  Eigen::Vector3d pattern_bgr = Eigen::Vector3d(25, 25, 25);
  Eigen::Vector3d orientation_rvec = Eigen::Vector3d::Zero();
  double radius_m() const { return 0.5 * diameter_m; }
};

// A path on the ground: waypoints (x, y) followed at speed_mps (or speeds_mps per leg), back and
// forth, starting at start_s. One waypoint: standing still.
struct PathSpec {
  std::vector<Eigen::Vector2d> waypoints_m;
  double speed_mps = 1.4;
  std::vector<double> speeds_mps;  // optional, one per leg (waypoints - 1)
  double start_s = 0.0;
};

// A robot: a dark vertical cylinder with a lighter top. handler: two dark arms at ball height
// reaching out towards heading_deg (degrees from +x towards +y) that hold a ball between them
// (BallSpec::held_by), pressed against the robot's side.
struct RobotSpec {
  PathSpec path;
  double radius_m = 0.25;
  double height_m = 0.8;
  Eigen::Vector3d colour_bgr = Eigen::Vector3d(35, 35, 35);
  bool handler = false;
  double heading_deg = 0.0;
};

// A person: an articulated figure (legs, arms, torso as capsules, head sphere) in the team's
// colours, swinging arms and legs with the gait; faster than 2.5 m/s is running.
struct PersonSpec {
  int id = 1;
  int team = 0;  // index into SceneSpec::teams
  PathSpec path;
  double height_m = 1.8;
  Eigen::Vector3d skin_bgr = Eigen::Vector3d(140, 170, 215);
};

struct TeamSpec {
  std::string name = "red";
  Eigen::Vector3d shirt_bgr = Eigen::Vector3d(40, 40, 200);
  Eigen::Vector3d shorts_bgr = Eigen::Vector3d(240, 240, 240);
};

// A static cone on the ground (a distractor, coloured near the ball).
struct ConeSpec {
  Eigen::Vector2d position_m = Eigen::Vector2d::Zero();
  double height_m = 0.3;
  double base_radius_m = 0.12;
  Eigen::Vector3d colour_bgr = Eigen::Vector3d(0, 80, 255);
};

// Light: direction towards the light (or, when sun_elevation_deg > 0, the sun at that elevation
// above the horizon and azimuth from +x towards +y). Objects are shaded 0.5 + 0.6 cos(angle to the
// light) (ball, robots, people) or 0.55 + 0.5 cos (goals, cones); with ambient in [0, 1] instead
// ambient + (1 - ambient) max(0, cos): the side away from the sun at `ambient` of the lit side.
// Exposure drift: gain 1 + gain_amplitude sin(2 pi t / period_s); white balance drift: blue gain
// 1 + w, red gain 1 - w with w = white_balance_amplitude sin(2 pi t / white_balance_period_s).
struct LightingSpec {
  Eigen::Vector3d light_dir = Eigen::Vector3d(0.35, 0.25, 1.0);
  double sun_elevation_deg = 0.0;  // 0: use light_dir
  double sun_azimuth_deg = 0.0;
  double ambient = -1.0;  // < 0: the fixed shading above
  double gain_amplitude = 0.0;
  double period_s = 10.0;
  double white_balance_amplitude = 0.0;
  double white_balance_period_s = 10.0;
  double vignetting = 0.15;  // brightness lost at the image corners
  bool shadows = true;
  // Unit vector towards the light (from the sun angles or light_dir).
  Eigen::Vector3d Direction() const;
};

struct SceneSpec {
  std::string field = "robocup-msl";  // built-in name or JSON path (fv::field::LoadField)
  std::vector<CameraSpec> cameras;
  double fps = 60.0;
  int num_frames = 60;
  uint64_t seed = 1;
  double exposure_s = 0.0;  // motion blur of the ball; 0: sharp
  BallSpec ball;
  std::vector<RobotSpec> robots;
  std::vector<PersonSpec> people;
  std::vector<TeamSpec> teams = {
      TeamSpec{}, TeamSpec{"blue", Eigen::Vector3d(180, 90, 20), Eigen::Vector3d(40, 30, 30)}};
  std::vector<ConeSpec> cones;
  LightingSpec lighting;
  double noise_sigma = 2.0;  // Gaussian sensor noise, 8-bit levels
  int jpeg_quality = 90;     // libjpeg's scale (cv::imwrite's), also for the MJPG frames of "avi"
  // "avi" (MJPG), "mp4" (H.264 as OpenCV's FFmpeg writes it, its encoder's default quality: what
  // compression costs), "png" or "jpg" (image sequence <cam>/%05d.ext).
  std::string format = "avi";

  double duration_s() const { return num_frames / fps; }
  // Throws fv::Error naming the bad key (e.g. "cameras[1].width must be > 0").
  void Check() const;
};

nlohmann::json SceneSpecToJson(const SceneSpec& spec);
// Missing keys take the defaults above; "duration_s" may replace "num_frames". Throws fv::Error
// naming `context` and the bad key. The result is Check()ed.
SceneSpec SceneSpecFromJson(const nlohmann::json& j, const std::string& context);
SceneSpec ReadSceneSpec(const std::string& path);

// Names of the presets: static, kick, players, demo, low-sun (static with a low sun and a printed
// yellow ball), low-sun-kick (kick with that light and a spinning printed ball), fisheye (strong
// radial distortion, balls near the image edges), held (a ball held in a robot's handler).
std::vector<std::string> PresetNames();
// A preset scene (see PresetNames); random parts (placements, paths) follow `seed`.
SceneSpec Preset(const std::string& name, uint64_t seed = 1);

// Rational-model distortion (OpenCV's 8 coefficients, k1 k2 p1 p2 k3 k4 k5 k6) close to an
// equidistant fisheye (r = f theta) up to about 80 deg off axis; the focal length that gives an
// image width covering hfov_deg with it.
std::vector<double> FisheyeDistortion();
// Names of the ball patterns: none, print, pentagons.
std::vector<std::string> BallPatternNames();
double FisheyeFocalPx(int width, double hfov_deg);

// The same scene with every camera resized to width x height (focal length and principal point
// scaled, so the field of view is kept).
void ResizeCameras(SceneSpec& spec, int width, int height);

// Ball truth per camera at one frame.
struct BallCameraTruth {
  bool in_front = false;                            // centre in front of the camera
  Eigen::Vector2d uv_px = Eigen::Vector2d::Zero();  // projection of the centre (full model)
  double radius_px = 0.0;                           // apparent radius
  double visible_fraction = 0.0;  // share of the image disc inside the image and unoccluded
};

struct BallTruthFrame {
  int frame = 0;
  double time_s = 0.0;   // mid-exposure time = frame / fps
  bool present = false;  // false when the scene has no ball
  Eigen::Vector3d centre_m = Eigen::Vector3d::Zero();
  std::vector<BallCameraTruth> cameras;
  int n_cams = 0;  // cameras with the centre in front and visible_fraction >= 0.3
};

struct PlayerCameraTruth {
  bool in_image = false;  // some part of the figure is in the image
  double bb_left = 0, bb_top = 0, bb_width = 0, bb_height = 0;  // pixels, clipped to the image
  double visible_fraction = 0.0;  // unoccluded share of the figure's in-image pixels
};

struct PersonTruth {
  int id = 0;
  int team = 0;
  double x_m = 0.0, y_m = 0.0;
  std::vector<PlayerCameraTruth> cameras;
};

// An airborne arc between ground contacts (or kicks).
struct Flight {
  double t_start_s = 0.0, t_end_s = 0.0;
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();   // centre at the start contact (z = radius)
  Eigen::Vector3d landing = Eigen::Vector3d::Zero();  // centre at the end contact
  Eigen::Vector3d apex = Eigen::Vector3d::Zero();
  Eigen::Vector3d v0_mps = Eigen::Vector3d::Zero();
};
nlohmann::json FlightsToJson(const std::vector<Flight>& flights);

struct CameraFrameStats;  // internal
class BallTrajectory;     // ball_physics.h
struct BallSample;        // internal

// Renders a scene. Construction precomputes the pixel rays and backgrounds of all cameras (about
// a second per 1280x960 camera); every method is const and thread-safe.
class SceneRenderer {
 public:
  explicit SceneRenderer(const SceneSpec& spec);
  ~SceneRenderer();
  SceneRenderer(const SceneRenderer&) = delete;
  SceneRenderer& operator=(const SceneRenderer&) = delete;

  const SceneSpec& spec() const { return spec_; }
  const std::vector<camera::Camera>& cameras() const { return cameras_; }
  const field::FieldModel& field() const { return field_; }
  int num_frames() const { return spec_.num_frames; }
  double fps() const { return spec_.fps; }
  double FrameTime(int frame) const { return frame / spec_.fps; }

  // Exact ball centre at a time (the scene must have a ball).
  Eigen::Vector3d BallAt(double time_s) const;
  // The ball's turn (body to world) at a time: orientation_rvec, placements' seeded turns, spin.
  Eigen::Matrix3d BallOrientation(double time_s) const;
  BallTruthFrame BallTruth(int frame) const;
  // Every person of the scene (SceneSpec::people order).
  std::vector<PersonTruth> PlayerTruth(int frame) const;
  const std::vector<Flight>& Flights() const;

  // One CV_8UC3 BGR image per camera (lighting and noise included; no compression).
  std::vector<cv::Mat> Render(int frame) const;
  // One camera's image; `stats` (optional) receives the ball and player truth of that camera.
  cv::Mat RenderCamera(int camera, int frame, CameraFrameStats* stats = nullptr) const;
  // The truth of one camera at one frame without making the image.
  CameraFrameStats CameraTruth(int camera, int frame) const;
  // The background of a camera without moving objects, lighting or noise (and its depth, CV_32F,
  // metres along the ray, +inf for the sky).
  const cv::Mat& Background(int camera) const;
  const cv::Mat& BackgroundDepth(int camera) const;

  struct CameraData;  // internal

 private:
  cv::Mat RenderInternal(int camera, int frame, CameraFrameStats* stats, bool want_image) const;
  // The ball's centre and turn at sub-exposure times (about one per half pixel of motion).
  std::vector<BallSample> BallSamples(int camera, double t) const;
  SceneSpec spec_;
  field::FieldModel field_;
  std::vector<camera::Camera> cameras_;
  std::unique_ptr<BallTrajectory> trajectory_;
  std::vector<std::unique_ptr<CameraData>> data_;
  std::vector<int16_t> noise_table_;  // Gaussian noise values, indexed by a per-frame hash
};

// Per camera and frame: what RenderCamera measured.
struct CameraFrameStats {
  BallCameraTruth ball;
  std::vector<PlayerCameraTruth> players;  // in SceneSpec::people order
};

struct WriteSceneResult {
  std::string out_dir;
  std::vector<std::string> files;  // everything written
  int num_frames = 0;
  int num_cameras = 0;
  double seconds = 0.0;        // wall time of rendering and writing
  double setup_seconds = 0.0;  // precomputation of rays and backgrounds
  int frames_with_ball_in_2plus_cams = 0;
  std::string Summary() const;
};

// Renders every frame of every camera into out_dir (created): scene.json, <cam>.yaml,
// <cam>.avi (MJPG) or <cam>/%05d.png|jpg, truth.csv, truth_2d.csv, flights.json, players.csv and
// players_2d.csv (when there are people) and contact_sheet.png. Progress on stderr if asked.
WriteSceneResult WriteScene(const SceneSpec& spec, const std::string& out_dir,
                            bool progress = false);

// The first images of the cameras tiled with their names (tile width in pixels).
cv::Mat ContactSheet(const std::vector<cv::Mat>& images, const std::vector<std::string>& names,
                     int tile_width = 640);

}  // namespace fv::synth
