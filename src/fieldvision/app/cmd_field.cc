// `fieldvision field show|draw`: list a field's keypoints and lines, draw its top view.
#include <filesystem>
#include <iostream>

#include <fmt/format.h>

#include "fieldvision/app/command.h"
#include "fieldvision/field/field.h"
#include "fieldvision/field/field_draw.h"
#include "fieldvision/field/field_json.h"
#include "fieldvision/io/image_file.h"
#include "fieldvision/util/error.h"

namespace fv::app {
namespace {

struct FieldShowOptions {
  std::string field;
  bool json = false;
};

struct FieldDrawOptions2 {
  std::string field;
  std::string out;
  int width_px = 1600;
  bool names = true;
};

void ShowField(const FieldShowOptions& o) {
  const field::FieldModel f = field::LoadField(o.field);
  if (o.json) {
    std::cout << field::FieldToJson(f).dump(2) << "\n";
    return;
  }
  std::cout << fmt::format("{}: {}\n", f.name, f.description);
  std::cout << fmt::format("playing area {:.2f} x {:.2f} m, lines {:.3f} m, surround {:.1f} m\n",
                           f.length_m, f.width_m, f.line_width_m, f.surround_m);
  std::cout << fmt::format(
      "{} keypoints (x, y, z in metres; origin at the centre, x along the "
      "length, z up):\n",
      f.keypoints.size());
  for (const auto& k : f.keypoints) {
    std::cout << fmt::format("  {:<40s} {:9.3f} {:9.3f} {:7.3f}\n", k.name, k.position_m.x(),
                             k.position_m.y(), k.position_m.z());
  }
  std::cout << fmt::format("{} straight lines, {} arcs, {} goals, {} hoops\n", f.segments.size(),
                           f.arcs.size(), f.goals.size(), f.hoops.size());
}

void DrawFieldCommand(const FieldDrawOptions2& o) {
  const field::FieldModel f = field::LoadField(o.field);
  const field::TopView view = field::TopView::ForField(f, o.width_px - field::kTopViewFrameWidthPx);
  field::FieldDrawOptions d;
  d.keypoints = true;
  d.keypoint_names = o.names;
  const cv::Mat img = field::FrameTopView(
      field::DrawField(f, view, d), view,
      fmt::format("field '{}': origin at its centre, x along its length; dots: named keypoints "
                  "(red on the ground, yellow raised: goal posts, crossbars, hoops)",
                  f.name));
  io::WriteImage(o.out, img);
  std::cout << "wrote " << o.out << " (" << img.cols << "x" << img.rows << ")\n";
}

void Setup(CLI::App& app, int& exit_code) {
  CLI::App* field = app.add_subcommand("field", "Show or draw a field model (built-in or JSON)");
  field->require_subcommand(1);
  auto show_opts = std::make_shared<FieldShowOptions>();
  CLI::App* show = field->add_subcommand("show", "List a field's keypoints and lines");
  show->add_option("field", show_opts->field, "Built-in name or JSON file")->required();
  show->add_flag("--json", show_opts->json, "Print the whole model as JSON (the custom format)");
  show->callback([show_opts] { ShowField(*show_opts); });
  auto draw_opts = std::make_shared<FieldDrawOptions2>();
  CLI::App* draw = field->add_subcommand("draw", "Draw a field's top view with its keypoints");
  draw->add_option("field", draw_opts->field, "Built-in name or JSON file")->required();
  draw->add_option("--out", draw_opts->out, "Image to write (.png, .jpg)")->required();
  draw->add_option("--width", draw_opts->width_px, "Image width in pixels")
      ->check(CLI::Range(300, 20000));
  draw->add_flag("!--no-names", draw_opts->names, "Do not write keypoint names");
  draw->callback([draw_opts] { DrawFieldCommand(*draw_opts); });
}

FV_REGISTER_COMMAND(90, "field", Setup);

}  // namespace
}  // namespace fv::app
