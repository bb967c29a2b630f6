// libFuzzer target: the photometric file readers (IES LM-63 and EULUMDAT) and the sensor file
// reader, each given the input; a table that reads is unfolded into a small goniometric image. A
// bad file must end in bpm::Error; anything else is a finding.
#include <cstddef>
#include <cstdint>
#include <string>

#include "base/error.h"
#include "lights/photometric_file.h"
#include "path/sensors.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  for (int format = 0; format < 2; ++format) {
    try {
      const bpm::PhotometricData d =
          format == 0 ? bpm::parse_ies(text, "fuzz.ies") : bpm::parse_eulumdat(text, "fuzz.ldt");
      bpm::goniometric_image(d, 16);
    } catch (const bpm::Error&) {
    }
  }
  try {
    bpm::parse_sensors(text, "fuzz.txt");
  } catch (const bpm::Error&) {
  }
  return 0;
}
