// The committed reference values (reference/cases/*_reference.csv, see
// docs/report.md) compiled into the program, so `skybake report earth`
// needs no file from the source tree.
#pragma once

#include <string>
#include <vector>

#include "shaders_runtime/embedded_text.h"

namespace skybake {
extern const std::vector<EmbeddedText> kReferenceFiles;
}  // namespace skybake

namespace skybake::report {

// "<name>_reference.csv" for the atmosphere `name`, or null when none is committed.
const EmbeddedText* CommittedReference(const std::string& atmosphere_name);

}  // namespace skybake::report
