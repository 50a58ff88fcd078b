// Colour maps of a coverage layer on the field's top view (field_draw.h): cameras per point,
// best pair angle, expected 3D error; with the field lines, each camera's position, aim and
// footprint (its image border cast onto the layer's plane) and a legend strip below.
#pragma once

#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "fieldvision/camera/camera.h"
#include "fieldvision/field/field.h"
#include "fieldvision/plan/coverage.h"

namespace fv::plan {

enum class CoverageMapKind { kCount, kAngle, kError };

struct CoverageMapOptions {
  int width_px = 1400;     // image width (the legend strip is added below)
  double alpha = 0.7;      // opacity of the colour cells over the field
  bool footprints = true;  // draw each camera's footprint outline
  double err_scale_m =
      0.0;  // error at the top of the colour scale; 0: the layer's worst good error

  void Check() const;
};

cv::Mat DrawCoverageMap(const CoverageLayer& layer, CoverageMapKind kind,
                        const std::vector<camera::Camera>& cameras, const field::FieldModel& field,
                        const CoverageOptions& coverage, const CoverageMapOptions& options = {});

}  // namespace fv::plan
