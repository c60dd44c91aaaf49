// The accuracy knobs of a bake on the command line (orders, table sizes,
// integration samples, packing, threads), shared by every command that bakes
// (`bake`, `bench`), so they spell and check them one way.
#pragma once

#include <string>
#include <vector>

#include "bake/bake.h"

namespace CLI {
class App;
}

namespace skybake::cli {

struct BakeSettingsOptions {
  BakeSettings settings;
  std::string orders = std::to_string(BakeSettings().orders);  // a count or "auto"
  bool no_tail = false;
  bool preview = false;  // start from PreviewBakeSettings(); options given override it
  std::vector<int> transmittance_size, irradiance_size, scattering_size;

  // Registers the options on `command`; the values land in this object.
  void AddTo(CLI::App* command);
  // The settings the options describe, validated: UsageError for an --orders
  // that is neither a count nor auto, and for out-of-range values.
  BakeSettings Resolve() const;

 private:
  CLI::App* command_ = nullptr;
};

// A --wavelengths count (0: the atmosphere's own three; else as
// SpectralWavelengths takes, bake/spectral.h), checked as an option value:
// UsageError otherwise. Every command with --wavelengths checks it so.
void CheckWavelengthsOption(int wavelengths);

}  // namespace skybake::cli
