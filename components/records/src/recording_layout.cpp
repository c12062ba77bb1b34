#include "navbus/records/recording_layout.hpp"

namespace navbus::records {

std::string recordFileName(const std::string& topic) {
  std::string file = topic;
  for (char& c : file) {
    if (c == '/') c = '_';
  }
  return file + ".csv";
}

}  // namespace navbus::records
