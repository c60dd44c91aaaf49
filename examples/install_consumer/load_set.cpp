// Loads a set written by `skybake bake` (every file checked against the
// manifest) and prints its tables' sizes and its atmosphere's name.
#include <cstdio>
#include <exception>

#include "formats/lut_files.h"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: load_set DIR\n");
    return 1;
  }
  try {
    const skybake::LutSet luts = skybake::LoadLutSet(argv[1]);
    std::printf("atmosphere %s\n", luts.atmosphere.name.c_str());
    std::printf("transmittance %dx%d\n", luts.transmittance.width, luts.transmittance.height);
    std::printf("scattering %dx%dx%d\n", luts.scattering.width, luts.scattering.height, luts.scattering.depth);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "load_set: %s\n", e.what());
    return 3;
  }
  return 0;
}
