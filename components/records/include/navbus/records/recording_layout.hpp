// Where a CSV recording keeps each topic: one file per topic in the recording's directory, as
// `navbus record` writes them, `navbus replay` and `navbus import` read and write them, and the
// evaluation reads them.
#pragma once

#include <string>

namespace navbus::records {

/// The file of a topic in a CSV recording: the topic's name with "/" as "_", then ".csv".
std::string recordFileName(const std::string& topic);

}  // namespace navbus::records
