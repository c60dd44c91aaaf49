#include "report/reference_files.h"

namespace skybake::report {

const EmbeddedText* CommittedReference(const std::string& atmosphere_name) {
  const std::string file = atmosphere_name + "_reference.csv";
  for (const EmbeddedText& text : kReferenceFiles) {
    if (text.name == file) return &text;
  }
  return nullptr;
}

}  // namespace skybake::report
