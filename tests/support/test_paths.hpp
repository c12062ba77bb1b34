// Where the tests find the shipped files, the test data and the executables under test.
// The absolute paths are compiled into test_paths.cpp alone. A test file that spelled them out
// would preprocess differently in every clone and miss the compiler cache, which hashes the
// preprocessed text: a fresh clone would recompile every such test.
#pragma once

namespace navbus::test_paths {

const char* sourceDir();       ///< the checkout's root
const char* scenarioDir();     ///< sim/scenarios
const char* configDir();       ///< config
const char* credentialsDir();  ///< the DDS Security test credentials the build makes
const char* rinexDir();        ///< tests/data/rinex
const char* realDir();         ///< tests/data/real
const char* workDir();         ///< scratch space of the real-data tests, in the build tree
const char* rnx2rtkp();        ///< Debian's rnx2rtkp, or "...-NOTFOUND"
const char* convbin();         ///< Debian's convbin, or "...-NOTFOUND"
const char* sensorSimExe();
const char* filterExe();
const char* faultManagerExe();
const char* toolExe();  ///< navbus

}  // namespace navbus::test_paths
