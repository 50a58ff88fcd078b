// libFuzzer harness: the CSV/XML track and detection readers. The first byte picks the reader:
// BALL.csv (recon/ball_csv.h), TRACKS.csv or MOTChallenge (track/mot.h), detections CSV / det.txt
// (track/detection.h), PETS CVML XML (track/pets.h); the rest is the file.
#include "fieldvision/recon/ball_csv.h"
#include "fieldvision/track/detection.h"
#include "fieldvision/track/mot.h"
#include "fieldvision/track/pets.h"
#include "fieldvision/util/csv.h"
#include "fuzz/fuzz_common.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1) return 0;
  const std::string_view text(reinterpret_cast<const char*>(data) + 1, size - 1);
  fv::fuzz::ExpectErrorOrValue([&] {
    switch (data[0] % 5) {
      case 0: {
        const auto table = fv::util::CsvTable::Parse(std::string(text), "BALL.csv");
        (void)fv::recon::ParseBallTrack(table);
        break;
      }
      case 1:
        (void)fv::recon::ReadBallTrack(fv::fuzz::WriteInput(text, "BALL.csv"));
        break;
      case 2:
        (void)fv::track::ReadTracksCsv(fv::fuzz::WriteInput(text, "TRACKS.csv"));
        break;
      case 3:
        (void)fv::track::ReadDetectionsCsv(fv::fuzz::WriteInput(text, "det.txt"));
        break;
      default:
        (void)fv::track::ReadPetsCvml(fv::fuzz::WriteInput(text, "gt.xml"));
        break;
    }
  });
  return 0;
}
