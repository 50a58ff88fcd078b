#include "fieldvision/calib/board.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <map>
#include <mutex>

#include <fmt/format.h>
#include <opencv2/aruco/charuco.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "fieldvision/codecs/codecs.h"
#include "fieldvision/io/frame_source.h"
#include "fieldvision/io/video_source.h"
#include "fieldvision/util/error.h"
#include "fieldvision/util/strings.h"

namespace fv::calib {
namespace {

const std::map<std::string, int>& DictionaryNames() {
  static const std::map<std::string, int> kNames = {
      {"DICT_4X4_50", cv::aruco::DICT_4X4_50},
      {"DICT_4X4_100", cv::aruco::DICT_4X4_100},
      {"DICT_4X4_250", cv::aruco::DICT_4X4_250},
      {"DICT_4X4_1000", cv::aruco::DICT_4X4_1000},
      {"DICT_5X5_50", cv::aruco::DICT_5X5_50},
      {"DICT_5X5_100", cv::aruco::DICT_5X5_100},
      {"DICT_5X5_250", cv::aruco::DICT_5X5_250},
      {"DICT_5X5_1000", cv::aruco::DICT_5X5_1000},
      {"DICT_6X6_50", cv::aruco::DICT_6X6_50},
      {"DICT_6X6_100", cv::aruco::DICT_6X6_100},
      {"DICT_6X6_250", cv::aruco::DICT_6X6_250},
      {"DICT_6X6_1000", cv::aruco::DICT_6X6_1000},
      {"DICT_7X7_50", cv::aruco::DICT_7X7_50},
      {"DICT_7X7_100", cv::aruco::DICT_7X7_100},
      {"DICT_7X7_250", cv::aruco::DICT_7X7_250},
      {"DICT_7X7_1000", cv::aruco::DICT_7X7_1000},
      {"DICT_ARUCO_ORIGINAL", cv::aruco::DICT_ARUCO_ORIGINAL}};
  return kNames;
}

cv::Mat ToGrey(const cv::Mat& image) {
  if (image.channels() == 1) return image;
  cv::Mat grey;
  cv::cvtColor(image, grey, image.channels() == 4 ? cv::COLOR_BGRA2GRAY : cv::COLOR_BGR2GRAY);
  return grey;
}

// The smallest distance between neighbouring chessboard corners, in pixels.
double SmallestSquarePx(const std::vector<cv::Point2f>& corners, int cols, int rows) {
  double best = 1e9;
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      const cv::Point2f& p = corners[r * cols + c];
      if (c + 1 < cols) best = std::min(best, cv::norm(p - corners[r * cols + c + 1]));
      if (r + 1 < rows) best = std::min(best, cv::norm(p - corners[(r + 1) * cols + c]));
    }
  }
  return best;
}

}  // namespace

BoardType ParseBoardType(const std::string& name) {
  const std::string n = util::ToLower(name);
  if (n == "chessboard") return BoardType::kChessboard;
  if (n == "charuco") return BoardType::kCharuco;
  Throw("board '{}' is not known; use chessboard or charuco", name);
}

int DictionaryId(const std::string& name) {
  const auto it = DictionaryNames().find(name);
  FV_REQUIRE(it != DictionaryNames().end(),
             "board dictionary '{}' is not an OpenCV ArUco dictionary (e.g. DICT_4X4_50)", name);
  return it->second;
}

void BoardSpec::Check() const {
  const int min_size = type == BoardType::kChessboard ? 2 : 3;
  FV_REQUIRE(cols >= min_size && rows >= min_size, "board cols and rows must be >= {} (got {}x{})",
             min_size, cols, rows);
  FV_REQUIRE(std::isfinite(square_m) && square_m > 0, "board square must be > 0 m (got {})",
             square_m);
  FV_REQUIRE(square_m <= 1.0,
             "board square {} m is over 1 m: sizes are in metres ({} mm is --square {})", square_m,
             square_m, square_m / 1000);
  FV_REQUIRE(marker_m <= 1.0,
             "board marker {} m is over 1 m: sizes are in metres ({} mm is --marker {})", marker_m,
             marker_m, marker_m / 1000);
  if (type == BoardType::kCharuco) {
    FV_REQUIRE(std::isfinite(marker_m) && marker_m >= 0 && marker_m < square_m,
               "board marker (--marker {} m) must be smaller than its square (--square {} m): the "
               "marker sits inside a square",
               marker_m, square_m);
    FV_REQUIRE(DictionaryNames().count(dictionary) > 0,
               "board dictionary '{}' is not an OpenCV ArUco dictionary (e.g. DICT_4X4_50)",
               dictionary);
  }
}

std::string BoardSpec::Describe() const {
  if (type == BoardType::kChessboard) {
    return fmt::format("chessboard {}x{} inner corners, {:.1f} mm squares", cols, rows,
                       square_m * 1000);
  }
  return fmt::format("charuco {}x{} squares, {:.1f} mm squares, {:.1f} mm markers, {}", cols, rows,
                     square_m * 1000, (marker_m > 0 ? marker_m : 0.7 * square_m) * 1000,
                     dictionary);
}

std::vector<cv::Point3f> BoardSpec::CornerPositions() const {
  const int nc = type == BoardType::kChessboard ? cols : cols - 1;
  const int nr = type == BoardType::kChessboard ? rows : rows - 1;
  std::vector<cv::Point3f> pts;
  pts.reserve(static_cast<size_t>(nc) * nr);
  for (int r = 0; r < nr; ++r) {
    for (int c = 0; c < nc; ++c) {
      // ChArUco corner (c, r) sits at ((c + 1) * square, (r + 1) * square) in OpenCV's layout.
      const int off = type == BoardType::kChessboard ? 0 : 1;
      pts.emplace_back(static_cast<float>((c + off) * square_m),
                       static_cast<float>((r + off) * square_m), 0.0f);
    }
  }
  return pts;
}

void DetectOptions::Check() const {
  FV_REQUIRE(subpix_half_window_px >= 1 && subpix_half_window_px <= 50,
             "subpix_half_window_px must be in [1, 50] (got {})", subpix_half_window_px);
  FV_REQUIRE(search_max_width_px == 0 || search_max_width_px >= 160,
             "search_max_width_px must be 0 or >= 160 (got {})", search_max_width_px);
  CheckInRange(subpix_square_fraction, 0.0, 1.0, "subpix_square_fraction");
  FV_REQUIRE(min_charuco_corners >= 4, "min_charuco_corners must be >= 4 (got {})",
             min_charuco_corners);
}

BoardView DetectBoard(const cv::Mat& image, const BoardSpec& board, const DetectOptions& options,
                      const std::string& name) {
  board.Check();
  options.Check();
  FV_REQUIRE(!image.empty(), "image '{}' is empty", name);
  BoardView view;
  view.name = name;
  view.image_size = image.size();
  const cv::Mat grey = ToGrey(image);
  if (board.type == BoardType::kChessboard) {
    const cv::Size pattern(board.cols, board.rows);
    std::vector<cv::Point2f> corners;
    const int flags = cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_NORMALIZE_IMAGE;
    double scale = 1.0;
    bool found = false;
    if (options.search_max_width_px > 0 && grey.cols > options.search_max_width_px) {
      scale = static_cast<double>(options.search_max_width_px) / grey.cols;
      cv::Mat small;
      cv::resize(grey, small, cv::Size(), scale, scale, cv::INTER_AREA);
      found = cv::findChessboardCorners(small, pattern, corners, flags);
      if (found) {
        for (auto& c : corners) c = (c + cv::Point2f(0.5f, 0.5f)) / scale - cv::Point2f(0.5f, 0.5f);
      }
    }
    if (!found && (scale == 1.0 || options.full_resolution_retry)) {
      scale = 1.0;
      found = cv::findChessboardCorners(grey, pattern, corners, flags);
    }
    if (!found) return view;
    const double square_px = SmallestSquarePx(corners, board.cols, board.rows);
    int half = options.subpix_half_window_px;
    if (options.subpix_square_fraction > 0) {
      half =
          std::max(1, std::min(half, static_cast<int>(options.subpix_square_fraction * square_px)));
    }
    cv::cornerSubPix(grey, corners, cv::Size(half, half), cv::Size(-1, -1),
                     cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 30, 0.01));
    const auto all = board.CornerPositions();
    view.image_points = corners;
    view.object_points = all;
    view.corner_ids.resize(all.size());
    for (size_t i = 0; i < all.size(); ++i) view.corner_ids[i] = static_cast<int>(i);
    return view;
  }
  // ChArUco: markers, then the chessboard corners between them (interpolated by a local
  // homography and refined to sub-pixel by OpenCV).
  const auto dict = cv::aruco::getPredefinedDictionary(DictionaryNames().at(board.dictionary));
  const float marker =
      static_cast<float>(board.marker_m > 0 ? board.marker_m : 0.7 * board.square_m);
  const auto charuco = cv::aruco::CharucoBoard::create(
      board.cols, board.rows, static_cast<float>(board.square_m), marker, dict);
  std::vector<std::vector<cv::Point2f>> marker_corners;
  std::vector<int> marker_ids;
  cv::aruco::detectMarkers(grey, dict, marker_corners, marker_ids);
  if (marker_ids.empty()) return view;
  std::vector<cv::Point2f> corners;
  std::vector<int> ids;
  cv::aruco::interpolateCornersCharuco(marker_corners, marker_ids, grey, charuco, corners, ids);
  if (static_cast<int>(ids.size()) < options.min_charuco_corners) return view;
  view.image_points = corners;
  view.corner_ids = ids;
  for (int id : ids) view.object_points.push_back(charuco->chessboardCorners[id]);
  return view;
}

std::string LargerChessboardSeen(const cv::Mat& image, const BoardSpec& board) {
  if (board.type != BoardType::kChessboard || image.empty()) return "";
  cv::Mat grey = ToGrey(image);
  constexpr int kSearchWidthPx = 1280;  // as DetectOptions::search_max_width_px
  if (grey.cols > kSearchWidthPx) {
    cv::resize(grey, grey, cv::Size(), double(kSearchWidthPx) / grey.cols,
               double(kSearchWidthPx) / grey.cols, cv::INTER_AREA);
  }
  const int flags =
      cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_NORMALIZE_IMAGE | cv::CALIB_CB_FAST_CHECK;
  const auto found_at = [&](const cv::Size& size) {
    std::vector<cv::Point2f> corners;
    return cv::findChessboardCorners(grey, size, corners, flags);
  };
  // A board one row and one column larger holds both of these (a whole board not found with
  // either is rare; each try that fails costs a full search).
  cv::Size larger(board.cols + 1, board.rows);
  if (!found_at(larger)) {
    larger = {board.cols, board.rows + 1};
    if (!found_at(larger)) return "";
  }
  // Then the largest up to kMaxGrowth corners wider and taller that is found: OpenCV finds a
  // whole board reliably and its parts only at times (7x5 given on the 9x6 sample: 7x6 found, 8x6
  // not; the first step alone named 7x6).
  constexpr int kMaxGrowth = 4;
  std::vector<cv::Size> sizes;
  for (int dc = 0; dc <= kMaxGrowth; ++dc) {
    for (int dr = 0; dr <= kMaxGrowth; ++dr) {
      if (dc + dr > 0) sizes.emplace_back(board.cols + dc, board.rows + dr);
    }
  }
  std::stable_sort(sizes.begin(), sizes.end(),
                   [](const cv::Size& a, const cv::Size& b) { return a.area() > b.area(); });
  const auto found = std::find_if(sizes.begin(), sizes.end(), found_at);
  if (found != sizes.end()) larger = *found;
  return fmt::format("{}x{} inner corners", larger.width, larger.height);
}

LargerBoard LargerChessboardInViews(const std::vector<BoardView>& views, const ImageSource& source,
                                    const BoardSpec& board) {
  const auto first = std::find_if(views.begin(), views.end(),
                                  [](const BoardView& v) { return !v.image_points.empty(); });
  if (first == views.end()) return {};
  return {first->name,
          LargerChessboardSeen(source.Read(static_cast<int>(first - views.begin())), board)};
}

std::string BoardNotFoundHint(const cv::Mat& image, const BoardSpec& board) {
  if (board.type != BoardType::kCharuco) {
    return "(check --cols and --rows: inner corners, one fewer than the squares)";
  }
  const cv::Mat grey = ToGrey(image);
  // The dictionary that finds the most markers; of dictionaries that find as many (the smaller
  // ones are the first markers of the larger ones), the smallest.
  std::string best;
  size_t best_count = 0;
  int best_size = 0;
  for (const auto& [name, id] : DictionaryNames()) {
    const auto dict = cv::aruco::getPredefinedDictionary(id);
    std::vector<std::vector<cv::Point2f>> corners;
    std::vector<int> ids;
    cv::aruco::detectMarkers(grey, dict, corners, ids);
    const int size = dict->bytesList.rows;
    if (ids.size() > best_count || (ids.size() == best_count && size < best_size)) {
      best = name;
      best_count = ids.size();
      best_size = size;
    }
  }
  if (best_count < 3) {
    return "(no ArUco markers seen in its first image: check the board, --dictionary and "
           "--marker)";
  }
  const auto family = best.substr(0, best.rfind('_') + 1);
  if (board.dictionary.rfind(family, 0) == 0 && family != "DICT_") {
    return fmt::format("(its markers are {}'s as given: check --cols/--rows and --marker)",
                       board.dictionary);
  }
  return fmt::format("(its first image shows {} markers of {}, not {}: give --dictionary {})",
                     best_count, best, board.dictionary, best);
}

// A video read forward frame by frame (a frame source has no seek).
struct ImageSource::VideoReader {
  void Open(const std::string& spec) {
    source = io::OpenFrameSource(spec);
    next_frame = 0;
  }
  std::mutex mutex;
  std::unique_ptr<io::FrameSource> source;
  long long next_frame = 0;  // the frame the next read gives
};

void ImageSourceOptions::Check() const {
  FV_REQUIRE(max_video_frames >= 1, "max_video_frames must be >= 1 (got {})", max_video_frames);
}

ImageSource::ImageSource(const std::string& spec, const ImageSourceOptions& options) : spec_(spec) {
  options.Check();
  namespace fs = std::filesystem;
  FV_REQUIRE(!spec.empty(), "images: no folder, pattern or video given");
  if (spec.find_first_of("*?[") != std::string::npos) {
    std::vector<cv::String> found;
    try {
      cv::glob(spec, found, false);
    } catch (const cv::Exception&) {
      found.clear();
    }
    for (const auto& f : found) {
      if (io::IsImageFile(f)) names_.push_back(f);
    }
    std::sort(names_.begin(), names_.end());
    FV_REQUIRE(!names_.empty(), "images '{}': the pattern matches no image file", spec);
    return;
  }
  FV_REQUIRE(fs::exists(spec), "images '{}': no such file or folder", spec);
  if (fs::is_directory(spec)) {
    for (const auto& e : fs::directory_iterator(spec)) {
      const std::string path = e.path().string();
      if (e.is_regular_file() && io::IsImageFile(path)) names_.push_back(path);
    }
    std::sort(names_.begin(), names_.end());
    FV_REQUIRE(!names_.empty(), "images '{}': the folder has no image files", spec);
    return;
  }
  if (io::IsImageFile(spec)) {
    names_.push_back(spec);
    return;
  }
  video_ = std::make_shared<VideoReader>();
  long long count = 0;
  try {
    video_->Open(spec);
    count = video_->source->FrameCount();
    if (count <= 0) {  // some containers do not say; count by reading
      count = 0;
      while (video_->source->SkipFrame()) ++count;
      video_->Open(spec);
    }
  } catch (const Error&) {
    Throw("images '{}': not an image, folder, pattern or readable video", spec);
  }
  FV_REQUIRE(count > 0, "images '{}': the video has no readable frames", spec);
  const int n = static_cast<int>(std::min<long long>(count, options.max_video_frames));
  for (int i = 0; i < n; ++i) {
    const int frame = static_cast<int>((count * (2LL * i + 1)) / (2LL * n));
    frames_.push_back(frame);
    names_.push_back(fmt::format("{}#{}", spec, frame));
  }
}

cv::Mat ImageSource::Read(int i) const {
  FV_REQUIRE(i >= 0 && i < size(), "images '{}': index {} out of range", spec_, i);
  cv::Mat image;
  if (!video_) {
    try {
      image = codecs::ImRead(names_[i], cv::IMREAD_UNCHANGED);
    } catch (const cv::Exception&) {
      image.release();
    }
    FV_REQUIRE(!image.empty(), "image '{}' cannot be read (missing or corrupt)", names_[i]);
    if (image.depth() != CV_8U) {
      cv::Mat converted;
      image.convertTo(converted, CV_8U, image.depth() == CV_16U ? 1.0 / 256 : 1.0);
      image = converted;
    }
    return image;
  }
  std::lock_guard<std::mutex> lock(video_->mutex);
  if (frames_[i] < video_->next_frame) video_->Open(spec_);
  bool ok = true;
  while (ok && video_->next_frame < frames_[i]) {
    ok = video_->source->SkipFrame();
    ++video_->next_frame;
  }
  long long frame = 0;
  double time_s = 0;
  ok = ok && video_->source->Read(&image, &frame, &time_s);
  video_->next_frame = ok ? frames_[i] + 1 : std::numeric_limits<long long>::max();
  FV_REQUIRE(ok && !image.empty(), "video '{}': frame {} cannot be read (corrupt video?)", spec_,
             frames_[i]);
  return image;
}

}  // namespace fv::calib
