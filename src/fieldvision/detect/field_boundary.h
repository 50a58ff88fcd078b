// The field's far edge in an image from a camera on or beside the field whose pose is unknown (a
// robot's camera, a phone photo): what lies above it (ceiling lamps, stands, banners) is not on
// the field. Per sampled column, scanning up from the bottom, the row that maximises field-colour
// pixels minus other pixels below it (a field boundary spot: lines, robots and the ball are
// gaps the field above them outweighs, a green shirt in the stands is not reached); then the
// highest spot within a window of columns, so that robots and goals standing on the far edge do
// not pull it down. Where the colour spec's field class finds too little, the image's own field
// colour (image_field.h: a teal or grey carpet). The field-boundary spots of RoboCup robot vision
// (B-Human's and others' field-boundary detection) without the model fit: a ball in the air lies
// above it too.
#pragma once

#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "fieldvision/detect/colour.h"
#include "fieldvision/detect/image_field.h"

namespace fv::detect {

struct FieldBoundaryOptions {
  int columns = 128;              // columns sampled across the region (fewer in a narrow one)
  double window_share = 0.1;      // the highest spot within this share of the width each side
  double min_field_share = 0.05;  // field-colour share of the sampled pixels for a boundary
  double min_column_share = 0.3;  // share of columns with a spot for a boundary (a column
                                  // without one leaves its window unbounded)
  // Where the colour spec's field class finds too little field: the image's own field colour.
  ImageFieldOptions image_field;
  // Throws fv::Error naming the bad field.
  void Check() const;
};

class FieldBoundary {
 public:
  FieldBoundary() = default;  // no boundary: nothing is above it
  // The boundary through (xs[i], ys[i]) (image column, row), xs increasing, at least one; throws
  // fv::Error otherwise.
  FieldBoundary(std::vector<double> xs, std::vector<double> ys);
  bool valid() const { return !xs_.empty(); }
  // The boundary's row at column x (linear between spots, the end spots beyond them); -inf
  // without a boundary.
  double RowAt(double x) const;
  // How far a point (x, y) lies above the boundary, in pixels (negative: below it).
  double Above(double x, double y) const { return RowAt(x) - y; }
  // Whether a disc lies off the field: its lowest point more than its radius above the boundary.
  bool DiscAbove(double x, double y, double radius) const { return Above(x, y + radius) > radius; }
  std::string Summary() const;

 private:
  std::vector<double> xs_, ys_;
};

// The boundary of the field class `field_bit` of `table` (0: none) in `roi` of a BGR image (the
// whole image when empty; nothing outside it is read), else of the image's own field colour
// (image_field.h); no boundary (valid() false) when too little of it is field-coloured.
FieldBoundary FindFieldBoundary(const cv::Mat& bgr, const ColourTable& table, uint8_t field_bit,
                                const FieldBoundaryOptions& options = {},
                                const cv::Rect& roi = cv::Rect());

}  // namespace fv::detect
