// The ball detector of one camera: colour lookup table (colour.h) -> scanlines, runs and blobs
// (blobs.h) -> shape and size filters -> sub-pixel centre from the outline (ball_fit.h). With a
// calibrated camera it also checks the size a ball of the given diameter has at that place in
// the image (on the ground and anywhere along the ray up to max_height_m) and, with a field,
// ignores everything outside the field of play (the image of the prism over the field up to
// max_height_m). Method after the RoboCup colour-segmentation pipelines (e.g. CMVision, Bruce et
// al., IROS 2000; B-Human's ball perceptor).
#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "fieldvision/camera/camera.h"
#include "fieldvision/detect/background.h"
#include "fieldvision/detect/ball_fit.h"
#include "fieldvision/detect/ball_region.h"
#include "fieldvision/detect/blobs.h"
#include "fieldvision/detect/colour.h"
#include "fieldvision/detect/field_boundary.h"
#include "fieldvision/detect/field_brightness.h"
#include "fieldvision/detect/field_surround.h"
#include "fieldvision/detect/image_field.h"
#include "fieldvision/detect/small_ball.h"
#include "fieldvision/field/field.h"

namespace fv::detect {

struct BallCandidate {
  Eigen::Vector2d centre_px = Eigen::Vector2d::Zero();
  double radius_px = 0.0;
  double sigma_px = 0.0;  // standard deviation of the centre, pixels (each axis)
  double score = 0.0;     // 0..1, higher is more ball-like
  bool accepted = false;  // passed every filter
  // Not accepted, but a fitted disc of a plausible size that failed only an outline check
  // (colour beyond the circle, dents, fit RMS, leak): a ball in front of a same-coloured or
  // dark background often looks like this. Multi-view fusion may use it to complete a position
  // that an accepted candidate of another camera starts (recon/triangulation.h).
  bool weak = false;
  // The region passed every shape check and the size check (a disc of a plausible size), whatever
  // the colour checks (leak, contrast) said: worth a second opinion (dnn_ball.h).
  bool disc_shaped = false;
  // Extras for drawing and diagnosis.
  double visible_fraction = 0.0;  // share of the fitted disc with the ball's colour
  double inlier_fraction = 0.0;   // share of rays with an outline point on the fit
  double outside_fraction = 0.0;  // share of rays where the colour goes on beyond the fit
  int dents = 0;                  // arcs of the outline inside the fit
  bool blurred = false;
  // The region check (ball_region.h): the blob taken whole, holes filled, a circle on its convex
  // outline.
  bool region_ok = false;
  double arc_cover = 0.0;        // share of the circle's angle with outline on it
  double fill = 0.0;             // share of the disc in the region
  double spill = 0.0;            // region beyond the circle, as a share of the disc
  double leak = 0.0;             // ball colour in a ring around the circle
  double contrast = 0.0;         // CIELAB distance between the disc's and the ring's colours
  double hue_contrast = 0.0;     // its hue part (CIE94 Delta H)
  double chroma_contrast = 0.0;  // the disc's chroma minus the ring's (CIELAB C*)
  double region_outside = 0.0;   // convex outline beyond the region's circle
  double region_extent = 0.0;    // the convex outline's far reach, in radii
  bool precise = false;          // the centre is the sub-pixel outline fit's (else the region's)
  bool small = false;            // found by the small-ball stage (small_ball.h)
  bool guided = false;           // fitted where a tracker expected the ball (FitAt)
  // Not accepted, its lowest point more than its radius above the field's far edge (no posed
  // camera): a network confirms it only as a ball of its own (set by "both", dnn_ball.h).
  bool off_field = false;
  // Rejected by the colour checks and accepted on a network confirmation below the network's
  // own accept score ("both", dnn_ball.h): multi-view fusion takes it as weak (ball_job.cc).
  bool rescued = false;
  // The network's sports-ball score (dnn_ball.h; 0 where it found none or did not look, -1 when
  // the detector has no network).
  double network_score = -1.0;
  // The share of a ring just around it that is field (BallDetector::FieldShare), where "both"
  // measured it for its keep rule (DnnBallOptions::keep_field_share); -1 elsewhere.
  double field_share = -1.0;
  // It stands apart from the camera's background (background.h); measured only where the colour
  // contrast was low or several candidates were accepted (BallDetector::SetBackground).
  bool apart_from_background = false;
  // The share of its disc that differs from the camera's background (Background::Compare): near
  // 1 for a thing that came into view, near 0 for one that was always there; -1 where it was not
  // compared.
  double background_change = -1.0;
  std::string reason;  // why rejected ("" when accepted)
};

struct BallDetectorOptions {
  double diameter_m = 0.22;       // ball diameter (size check with a calibrated camera)
  std::string colour = "orange";  // preset name or colour file (LoadColourSpec)
  int lut_bits = 8;               // bits per channel of the lookup table: 8 exact, 5..7 quantised
  int scan_step_px = 2;           // scanline step (rows and columns)
  int min_samples = 2;            // smallest blob, in scan samples
  double min_radius_px = 2.0;     // ball radius limits in the image
  double max_radius_px = 150.0;
  double min_fill_ratio = 0.35;       // blob area / bounding box (pi/4 for a disc; lower: occluded)
  double max_aspect_ratio = 3.0;      // blob bounding box long / short side
  double min_inlier_fraction = 0.45;  // rays whose outline point lies on the fitted circle
  double max_fit_rms_px = 0.8;        // RMS of those outline points
  int max_dents = 2;  // arcs of the outline inside the circle (occluders), when < 85 % fit
  double min_visible_fraction = 0.35;  // ball-coloured share of the fitted disc
  double max_leak_fraction = 0.35;     // ball-coloured share of a ring just outside it
  double max_outside_fraction = 0.15;
  // A partly hidden ball (under 75 % of rays on the circle) must not spill beyond it at all.
  double max_outside_fraction_occluded =
      0.03;                     // rays where the colour goes on beyond the fitted circle
  double size_tolerance = 0.3;  // relative slack of the expected radius (calibrated camera)
  double max_height_m = 8.0;    // highest ball centre considered (size check and field mask)
  double min_distance_m = 0.5;  // nearest ball distance to the camera considered
  bool use_field_mask = true;   // with camera pose and field: only the field of play
  double field_margin_m = 1.0;  // around the field of play
  int max_refine = 24;          // blobs refined per frame (disc-like ones first, then largest)
  // The region check (real balls: print, highlights, shading, occlusion, small and blurred):
  // accepted when the circle on the region's convex outline is covered on this share of its
  // angle, the disc is filled this much, little spills beyond it and little ball colour lies
  // around it.
  bool use_region = true;
  double min_arc_cover = 0.5;
  // Without a posed camera (a photo, a robot's camera) the off-field and lit-part checks carry
  // part of the decision, so a region covering this share of its circle will do: a ball whose
  // shaded lower half, or a part hidden by a robot or a foot, is not in the class. With a posed
  // camera the tracker's fit at the expected size finds such a ball, and a centre from under half
  // a circle is too far off to triangulate (low-sun-kick at 0.4: median 2.35 -> 3.89 mm). Measured
  // on the photos (0.5 / 0.45 / 0.4 / 0.3): MSL recall 0.701 / 0.718 / 0.744 / 0.752 at precision
  // 0.988 / 0.977 / 0.978 / 0.967, SSL 0.805 / 0.811 / 0.814 / 0.814 at 0.943 / 0.940 / 0.937 /
  // 0.934; below 0.45 a square's inscribed circle passes (0.42 of it covered by the sides).
  double unposed_min_arc_cover = 0.45;
  double min_region_fill = 0.5;
  double max_region_spill = 0.25;
  double max_ring_leak = 0.3;
  double max_region_outside = 0.1;  // convex outline points beyond the circle (corners, apexes)
  // The convex outline's far reach from the centre, in radii (1.41: a square's corners).
  double max_region_extent = 1.25;
  // A ball stands out from its surroundings: CIELAB Delta E between the median colours of the
  // disc's ball-class pixels and of a ring (ball_region.h) of at least min_contrast, or a hue
  // difference (CIE94 Delta H: a shaded ball stays of its hue) of at least min_hue_contrast,
  // required of every accepted candidate with a region; a candidate's score grows with its
  // contrast up to twice min_contrast. Chosen on the real SSL and MSL photos as a whole and the
  // low-sun renders (min_contrast 35-45, min_hue_contrast 20-30 tried).
  double min_contrast = 40.0;
  double min_hue_contrast = 25.0;
  // Or, against a neutral surround (a ring of CIELAB chroma at most max_neutral_ring_chroma and
  // lightness at least min_neutral_ring_lightness: grey stands, a white wall), by being more
  // colourful than it by min_chroma_contrast: a shaded yellow ball against grey stands differs
  // from them in chroma alone (Delta E 34-39, Delta H near 0). A dark ring is no neutral
  // surround: any lit coloured spot (a robot's LED) is more colourful than black. Measured on
  // the low-sun renders (detector alone, whole frames, balls >= 70 % visible; seeds 1, 6, 2, 3)
  // at min_chroma_contrast off / 25 / 30 / 35: 50 / 58 / 57 / 51 of 64, 53 / 57 / 57 / 54 of 63,
  // 50 / 53 / 53 / 51 of 64, 53 / 58 / 57 / 54 of 64; photos unchanged at 30 and 35 (SSL 0.863 /
  // 0.940, MSL 0.709 / 0.976), at 25 MSL two more false detections. Without the lightness limit
  // an SSL robot's LED passes; the chroma limit (10 / 15 / 20 measured alike) keeps a saturated
  // disc on a pale wall of its own hue out.
  double min_chroma_contrast = 30.0;
  double max_neutral_ring_chroma = 12.0;
  double min_neutral_ring_lightness = 20.0;
  // A ball on the field (at least min_field_ring of the ring in the colour spec's field or line
  // classes) is set apart by the classes themselves and needs field_contrast_factor x those
  // contrasts: a yellow ball in a greenish camera is a yellow-green disc on green. Measured
  // (min_field_ring 0.6 / 0.7 / 0.8, factor 0.5, against no relaxation): MSL photos recall 0.701
  // / 0.675 / 0.658 against 0.641 at precision 0.89 / 0.88 / 0.89 (0.88); low-sun-kick render
  // found 145 / 156 / 156 of 192 (140), positions 0.5 m off 9 / 6 / 6 (6).
  double min_field_ring = 0.7;
  // ... of which at least this share is the field's own colour, not its lines: a ring of white
  // alone is as likely a wall.
  double min_grass_ring = 0.1;
  double field_contrast_factor = 0.5;
  // Whether a failed region shape check also rejects a candidate whose sub-pixel outline fit
  // passed all its own checks.
  bool region_vetoes_fit = false;
  BallRegionOptions region;
  // The region grows through the ball class widened by this hue (degrees) and with saturation
  // and value minima times grow_factor (colour.h: WidenedBallSpec); grow_factor 1 and
  // grow_hue_deg 0 keep the class as it is.
  double grow_hue_deg = 4.0;
  double grow_factor = 0.6;
  // Weak candidates (see BallCandidate::weak) need at least this share of rays on the circle.
  double weak_min_inlier_fraction = 0.5;
  // FitAt (a tracked ball's expected place): the fitted radius within this share of the expected
  // one, the centre within this many expected radii of the expected place.
  double guided_radius_change = 0.2;
  double guided_max_shift_radii = 1.0;
  BallFitOptions fit;
  // Balls of a few pixels whose colour is mixed with the background (small_ball.h).
  SmallBallOptions small;
  // Without a posed camera such a spot is accepted only on the field (field_surround.h): LEDs on
  // robots, marks on boards and lights over the stands are framed by other colours. Measured on
  // the photos (`--small-balls on`): SSL precision 0.926 -> 0.939 at recall 0.845, MSL 0.913 ->
  // 0.977 at 0.718 (min_share 0.3..0.8 the same; with the lines' class as field SSL 0.933).
  FieldSurroundOptions small_field;
  // Without a posed camera (a robot's camera, a photo): a candidate whose lowest point lies more
  // than its radius above the field's far edge (field_boundary.h, found with the colour spec's
  // "field" class) is accepted only from this score (0: no check), or as a whole disc: its region
  // found, at least off_field_min_visible of the disc in the ball's colour (a ball in the air is
  // seldom hidden: what hides a ball stands on the ground) and a radius of at least
  // off_field_min_radius_px (a few pixels' spot of a lamp's colour has no shape to judge).
  // Above the field, lamps, shirts and banners of the ball's colour are far more common than a
  // ball in the air; a network's confirmation (--detector both) still accepts one. Measured on
  // the real photos against no check: MSL colour precision 0.889 -> 0.964 at recall 0.684 (score
  // alone: 0.974 at 0.650, the lobbed balls over the stands lost; visible share 0.5 / 0.7: 0.952
  // at 0.684 / 0.963 at 0.667), SSL 0.892 -> 0.923 at recall 0.808 -> 0.805.
  double off_field_min_score = 0.6;
  double off_field_min_visible = 0.6;
  double off_field_min_radius_px = 4.0;
  FieldBoundaryOptions field_boundary;
  // Without a posed camera (no size check): a ball reflects more than the grass or carpet it
  // lies on (field_brightness.h), so an accepted candidate whose lit part (the 90th percentile
  // of V over its disc) is darker than min_lit_field_ratio x the field's median V in the searched
  // region is rejected (an orange LED on a dark robot, a robot's part, a logo). 0: no check; off
  // for the black, blue and green presets (balls that need not be brighter than the field).
  // Light from above (a hall, the sun high) shows a camera the lit side; a low sun behind the
  // ball shows it the shaded side, darker than the sunlit grass (the low-sun renders: 44 of 174
  // balls of one camera): turn it off there. Measured on the real photos (ratio 1.0): no ball
  // below it; SSL colour precision 0.923 -> 0.933, MSL 0.965 -> 0.988 at the same recall.
  double min_lit_field_ratio = 1.0;
  FieldBrightnessOptions field_brightness;
  // Throws fv::Error naming the bad field.
  void Check() const;
};

struct BallDetectionResult {
  std::vector<BallCandidate> candidates;  // best first
  int blobs = 0;
  int runs = 0;
  long long samples = 0;
  int refined = 0;
  int accepted() const;
  std::string Summary() const;
};

// A static camera's background (background.h), built on the first call; null when there is none
// or it is not usable. Must be safe to call from several threads.
using BackgroundFn = std::function<const Background*()>;

class BallDetector {
 public:
  // camera: null for an uncalibrated camera (no size check, no field mask, pixel-space fit);
  // a camera without a pose gives the perspective fit but no size check or mask. field: null for
  // no field mask. Both must outlive the detector. Throws fv::Error on bad options or colour.
  BallDetector(const BallDetectorOptions& options, const camera::Camera* camera,
               const field::FieldModel* field);
  // Same, with an explicit colour spec (options.colour is ignored).
  BallDetector(const BallDetectorOptions& options, const ColourSpec& colour,
               const camera::Camera* camera, const field::FieldModel* field);

  // All candidates found in a BGR frame, best first; accepted ones passed every filter.
  // Thread-safe (const). Throws fv::Error when the frame is empty, not BGR, or not the camera's
  // size. `region` (optional): search only there (a window around a tracked ball); pixels
  // outside it are not read, and blobs too near its inner edges to be fitted are left out.
  std::vector<BallCandidate> Detect(const cv::Mat& bgr, const cv::Rect& region = cv::Rect()) const;
  BallDetectionResult DetectWithSummary(const cv::Mat& bgr,
                                        const cv::Rect& region = cv::Rect()) const;

  // A ball where a tracker expects one (`centre_px`, `radius_px`: its prediction), for a frame
  // where Detect accepted none there (a ball merged with a neighbour of its colour, or passing
  // over one): the outline fit in the widened ball class seeded there, else a circle on colour
  // edges (edge_circle.h), accepted when it is of about that radius near that place
  // (guided_radius_change, guided_max_shift_radii) with enough ball colour inside and the size
  // check passed; no region, leak or contrast checks. Reads nothing outside `region` (empty: the
  // frame); nullopt when no outline agrees.
  std::optional<BallCandidate> FitAt(const cv::Mat& bgr, const cv::Rect& region,
                                     const Eigen::Vector2d& centre_px, double radius_px) const;
  // A region that does not stand out from its surroundings by colour (min_contrast and the
  // others) is still taken as standing out when it stands apart from the camera's background, and
  // among several accepted candidates those apart from it go first; `background` is called only
  // then. Set before detecting, not during.
  void SetBackground(BackgroundFn background) { background_ = std::move(background); }
  const BallDetectorOptions& options() const { return options_; }
  const ColourTable& table() const { return *table_; }
  // The field's far edge the off-field check uses in `region` of a frame (field_boundary.h); no
  // boundary when the check is off (a posed camera, off_field_min_score 0).
  FieldBoundary OffFieldBoundary(const cv::Mat& bgr, const cv::Rect& region = cv::Rect()) const;
  // The field-of-play mask (CV_8U, 255 inside) or empty when not used.
  const cv::Mat& field_mask() const { return field_mask_; }
  // The image's own field colour of a frame (image_field.h), found at most once per frame.
  using ImageFieldCache = std::optional<std::optional<ImageFieldColour>>;
  // The share of a ring just around (centre_px, radius_px) that is field (field_surround.h,
  // options.small_field's ring; only its pixels in `roi` are read, empty: the frame): the field
  // class, or, where that holds less than `enough` there, the class or the image's own field
  // colour (found once into *image_field); negative when neither tells (no field class and no
  // field colour in the image, or no ring pixel in `roi`).
  double FieldShare(const cv::Mat& bgr, const cv::Rect& roi, const Eigen::Vector2d& centre_px,
                    double radius_px, double enough, ImageFieldCache* image_field) const;
  // Expected radius range [min, max] in pixels of the ball seen at `uv` (calibrated camera with
  // pose), or false when unknown.
  bool ExpectedRadius(const Eigen::Vector2d& uv, double* min_px, double* max_px) const;

 private:
  void Init(const ColourSpec& colour);
  // A calibrated camera with a pose: size checks, the field mask; without one the checks of a
  // photo (off-field, lit part, small spots on the field).
  bool posed() const { return camera_ != nullptr && camera_->has_pose; }
  // "" when `radius` fits the radius limits and the ball's size at `centre` (posed camera);
  // else why not. `size_factor` (0.5..1) prefers the size of a ball on the ground there.
  std::string SizeProblem(const Eigen::Vector2d& centre, double radius, double* size_factor) const;
  // FitAt's outline: the outline fit in `table`, else colour edges (edge_circle.h), agreeing with
  // the expected circle; nullopt when neither does.
  struct GuidedOutline {
    Eigen::Vector2d centre_px;
    double radius_px, sigma_px, rms_px, inlier_fraction;
  };
  std::optional<GuidedOutline> FitGuidedOutline(const cv::Mat& bgr, const ColourTable& table,
                                                uint8_t bit, const Eigen::Vector2d& centre_px,
                                                double radius_px) const;
  // The smallest radius (pixels) the size check accepts where the ball is expected at least
  // `expected_min_px` large (size_tolerance and half a pixel of slack).
  double SmallestPlausibleRadius(double expected_min_px) const;
  // The small-ball stage's spots in `roi` as candidates (accepted unless the camera expects a
  // larger ball there).
  void AddSmallBalls(const cv::Mat& bgr, const cv::Rect& roi, BallDetectionResult* result) const;
  // Small-ball candidates without a posed camera that do not lie on the field are rejected.
  void RejectSmallOffField(const cv::Mat& bgr, const cv::Rect& roi,
                           std::vector<BallCandidate>* candidates) const;
  // Rejects the accepted candidates that off_field_min_score rejects (without a posed camera);
  // `boundary` holds the frame's field boundary once found.
  void RejectOffField(const cv::Mat& bgr, const cv::Rect& roi,
                      std::optional<FieldBoundary>* boundary,
                      std::vector<BallCandidate>* candidates) const;
  // Among the accepted candidates (ranked), those above the field's far edge go after those on
  // the field (without a posed camera).
  void OnFieldFirst(const cv::Mat& bgr, const cv::Rect& roi, std::optional<FieldBoundary>* boundary,
                    std::vector<BallCandidate>* candidates) const;
  // With a background (SetBackground): a rejected region (the few whose disc changed most, by
  // area) may hold a ball that came into view merged with a board of its colour, or a ball whose
  // region failed its shape checks. The largest round part of its box that differs from the
  // background (Background::ChangedDisc), if not larger than the region, seeds FitAt there; a fit
  // that stands apart from the background is added, accepted.
  void AddApartInRejected(const cv::Mat& bgr, const cv::Rect& roi,
                          std::vector<BallCandidate>* candidates) const;
  // With a background (SetBackground) and more blobs than max_refine: those whose disc differs
  // from the background (half of it at least: a thing that came into view, a ball merged with a
  // board of its colour too) are refined first, ahead of the still things of the ball's colour
  // (boards, the stands, blocks of an H.264 video's artefacts) that would use up max_refine.
  void ChangedFirst(const cv::Mat& bgr, const cv::Rect& roi, std::vector<const Blob*>* order) const;
  // With a background (SetBackground) and several accepted candidates, those that stand apart
  // from it go first (a ball in play before still things of its colour and size).
  void ApartFirst(const cv::Mat& bgr, const cv::Rect& roi,
                  std::vector<BallCandidate>* candidates) const;
  // Rejects the accepted candidates darker than the field (min_lit_field_ratio).
  void RejectDarkerThanField(const cv::Mat& bgr, const cv::Rect& roi,
                             std::vector<BallCandidate>* candidates) const;
  // Whether the small-ball stage runs (options.small.mode; "auto": somewhere in the image a
  // posed camera expects a ball that small).
  bool SmallBallsPossible() const;
  // Centres and radii of the regions measured so far in a frame (a blob inside one is a
  // fragment of it).
  struct MeasuredRegions {
    std::vector<Eigen::Vector2d> centres;
    std::vector<double> radii;
    bool Holds(const BallRegion& region) const;
  };
  // One blob through the region stage, the outline fit and Decide: its candidate, or nullopt for
  // a fragment of a region already measured. Counts refined blobs in `refined` (max_refine).
  std::optional<BallCandidate> EvaluateBlob(const cv::Mat& bgr, const Blob& blob,
                                            const cv::Rect& roi, MeasuredRegions* measured,
                                            int* refined) const;
  // Accepts `cand` by the outline fit (precise) or the region checks, with the size check and
  // the score, or rejects it with the reason.
  void Decide(const BallRegion& region, const BallFit& fit, const std::string& fit_why,
              double visible, double leak, BallCandidate* cand) const;
  BallDetectorOptions options_;
  BackgroundFn background_;
  const camera::Camera* camera_;
  const field::FieldModel* field_;
  std::shared_ptr<const ColourTable> table_;
  // The widened ball class: region growing and the small spots' unmixed colour.
  std::shared_ptr<const ColourTable> grow_table_;  // table_ when the widened class is one of its
  uint8_t grow_bit_ = 0;                           // the widened class's bit in grow_table_
  uint8_t ball_bit_ = 1;
  uint8_t field_bit_ = 0;  // the spec's "field" class (0: none)
  cv::Mat field_mask_;
  bool small_balls_ = false;
  double min_arc_cover_ = 0.5;  // min_arc_cover, or unposed_min_arc_cover without a posed camera
  bool lit_check_ = false;      // min_lit_field_ratio applies (no posed camera, not a dark preset)
};

// The field-of-play mask of a camera: the image of the prism over the field (plus margin) from
// the ground to max_height_m. Empty when a corner of the prism is behind the camera.
cv::Mat FieldMask(const camera::Camera& camera, const field::FieldModel& field, double margin_m,
                  double max_height_m);

}  // namespace fv::detect
