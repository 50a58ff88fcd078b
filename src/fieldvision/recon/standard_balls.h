// The balls of the sports the fields are for, by official diameter and mass (ITTF, R&A/USGA,
// ITF, FIFA, FIBA), so that a ball's mass, which turns the fitted Magnus lift into a spin in
// rev/s, follows the diameter the user gives unless the mass is given too.
#pragma once

#include <string>

namespace fv::recon {

struct StandardBall {
  const char* name;
  double diameter_m;
  double mass_kg;
};

// The standard ball whose diameter is nearest to `diameter_m` (as a ratio); `diameter_m` > 0.
const StandardBall& NearestStandardBall(double diameter_m);

// "" when a ball of this mass and diameter has a mean density balls have (20..2000 kg/m^3:
// hollow balls about 80, a golf ball about 1130); else a one-line warning saying the density and
// that the spin in rev/s scales with the mass.
std::string BallMassWarning(double diameter_m, double mass_kg);

}  // namespace fv::recon
