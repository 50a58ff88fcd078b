// Calibration boards and their detection: OpenCV chessboards (inner corners, refined to sub-pixel
// with cv::cornerSubPix) and ChArUco boards (OpenCV contrib aruco; partial views count), plus the
// image sources a calibration reads (a folder, a glob pattern, a single image or a video sampled
// evenly). Method: Zhang-style planar targets, OpenCV calib3d "Camera calibration with OpenCV".
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace fv::calib {

enum class BoardType { kChessboard, kCharuco };

struct BoardSpec {
  BoardType type = BoardType::kChessboard;
  // Chessboard: inner corners per row (cols) and per column (rows). ChArUco: squares per row
  // and per column (OpenCV's squaresX, squaresY), so the board has (cols-1) x (rows-1) corners.
  int cols = 9;
  int rows = 6;
  double square_m = 0.025;
  // ChArUco only: marker side (0: 0.7 * square_m) and the ArUco dictionary name (DICT_4X4_50,
  // DICT_5X5_100, DICT_6X6_250, ... as in cv::aruco::PREDEFINED_DICTIONARY_NAME).
  double marker_m = 0.0;
  std::string dictionary = "DICT_4X4_50";

  // Throws fv::Error naming the bad field.
  void Check() const;
  // "chessboard 9x6 inner corners, 25.0 mm squares" and the like.
  std::string Describe() const;
  // Board corner positions (z = 0, metres), indexed by corner id (row-major).
  std::vector<cv::Point3f> CornerPositions() const;
};

// Parses "chessboard" or "charuco"; throws naming the value otherwise.
BoardType ParseBoardType(const std::string& name);

// OpenCV's id of an ArUco dictionary name (cv::aruco::PREDEFINED_DICTIONARY_NAME); throws naming
// the value otherwise.
int DictionaryId(const std::string& name);

struct DetectOptions {
  // cornerSubPix half window in pixels (cv::cornerSubPix's winSize; OpenCV's calibration sample
  // uses 11), capped at subpix_square_fraction x the smallest square seen so that the window does
  // not reach the neighbouring corners (0: no cap, exactly OpenCV's sample).
  int subpix_half_window_px = 11;
  double subpix_square_fraction = 0.45;
  // Chessboards are searched in a copy downscaled to at most this many pixels wide (0: never),
  // then corners are refined in the full image; big frames are found much faster.
  int search_max_width_px = 1280;
  // When the downscaled search fails, search the full image too (slower, finds small boards).
  bool full_resolution_retry = true;
  // ChArUco: a view needs at least this many interpolated corners.
  int min_charuco_corners = 6;

  void Check() const;
};

// The board as seen in one image: corner pixels and the matching board points.
struct BoardView {
  std::string name;  // file name or "video.mp4#frame"
  cv::Size image_size;
  std::vector<cv::Point2f> image_points;
  std::vector<cv::Point3f> object_points;
  std::vector<int> corner_ids;
};

// Finds the board; an empty optional-like result (image_points empty) when it is not seen.
BoardView DetectBoard(const cv::Mat& image, const BoardSpec& board, const DetectOptions& options,
                      const std::string& name);

// What to check when the board is found in none of a camera's images: for ChArUco, the predefined
// dictionary whose markers `image` shows most ("give --dictionary D" when it is not the board's),
// else the options that describe the board. One clause, "(...)".
std::string BoardNotFoundHint(const cv::Mat& image, const BoardSpec& board);

// A chessboard larger than `board` in `image`, where `board` was found in it: OpenCV finds a
// sub-board of the given size on a larger board, a different part in different views, which
// shifts the board's origin between views (harmless for intrinsics alone, wrong relative poses
// for a rig). "" when none (and for ChArUco, whose markers fix each corner's id), else a clause
// naming the larger size, "9x6 inner corners".
std::string LargerChessboardSeen(const cv::Mat& image, const BoardSpec& board);

// Image sources for calibration.
struct ImageSourceOptions {
  int max_video_frames = 60;  // a video is sampled evenly to at most this many frames
  void Check() const;
};

class ImageSource {
 public:
  // A folder (every .jpg/.jpeg/.png/.bmp/.tif/.tiff in it, sorted), a glob pattern
  // ("dir/left*.jpg"), one image, or a video. Throws fv::Error naming `spec` when nothing
  // matches or the file cannot be opened.
  explicit ImageSource(const std::string& spec, const ImageSourceOptions& options = {});
  int size() const { return static_cast<int>(names_.size()); }
  const std::string& spec() const { return spec_; }
  // "images", or for a video "frames sampled from the video" (for messages).
  std::string what() const { return video_ ? "frames sampled from the video" : "images"; }
  const std::string& name(int i) const { return names_[i]; }
  // Reads image i (BGR or grey as stored); throws naming the file when it cannot be read. A
  // video is read forward through io's frame source (reopened when i goes back).
  cv::Mat Read(int i) const;

 private:
  struct VideoReader;
  std::string spec_;
  std::shared_ptr<VideoReader> video_;  // null for images
  std::vector<std::string> names_;
  std::vector<int> frames_;  // video frame numbers
};

// LargerChessboardSeen on the first of `views` where the board was found, its image read again
// from `source` (the views' own, in order): that view's name and the larger size ("" when none,
// or when the board was found in no view).
struct LargerBoard {
  std::string view;
  std::string size;
};
LargerBoard LargerChessboardInViews(const std::vector<BoardView>& views, const ImageSource& source,
                                    const BoardSpec& board);

}  // namespace fv::calib
