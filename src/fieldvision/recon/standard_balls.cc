#include "fieldvision/recon/standard_balls.h"

#include <array>
#include <cmath>

#include <fmt/format.h>

#include "fieldvision/util/error.h"

namespace fv::recon {
namespace {

constexpr std::array<StandardBall, 6> kBalls = {{
    {"table-tennis", 0.040, 0.0027},
    {"golf (RoboCup SSL)", 0.04267, 0.04593},
    {"tennis", 0.0670, 0.0577},
    {"futsal", 0.200, 0.42},
    {"football (size 5)", 0.220, 0.43},
    {"basketball (size 7)", 0.239, 0.62},
}};

constexpr double kMinDensityKgpm3 = 20.0;
constexpr double kMaxDensityKgpm3 = 2000.0;

}  // namespace

const StandardBall& NearestStandardBall(double diameter_m) {
  FV_REQUIRE(std::isfinite(diameter_m) && diameter_m > 0,
             "ball diameter must be a positive number of metres (got {})", diameter_m);
  const StandardBall* best = &kBalls[0];
  for (const StandardBall& b : kBalls) {
    if (std::abs(std::log(diameter_m / b.diameter_m)) <
        std::abs(std::log(diameter_m / best->diameter_m))) {
      best = &b;
    }
  }
  return *best;
}

std::string BallMassWarning(double diameter_m, double mass_kg) {
  const double r = 0.5 * diameter_m;
  const double density = mass_kg / (4.0 / 3.0 * M_PI * r * r * r);
  if (density >= kMinDensityKgpm3 && density <= kMaxDensityKgpm3) return "";
  const StandardBall& like = NearestStandardBall(diameter_m);
  return fmt::format(
      "a ball of {:.3f} m and {:.4g} kg has a mean density of {:.0f} kg/m^3 (balls have "
      "{:.0f}-{:.0f}; {}: {:.3f} m, {:.4g} kg): the spin in rev/s scales with the "
      "mass; check --ball-mass and --ball-diameter",
      diameter_m, mass_kg, density, kMinDensityKgpm3, kMaxDensityKgpm3, like.name, like.diameter_m,
      like.mass_kg);
}

}  // namespace fv::recon
