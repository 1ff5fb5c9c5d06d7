// The paths the tests read — the data folders, the built command-line tool and the folder for the CLI tests'
// screenshots — defined in one source that tests/CMakeLists.txt generates per build. They are not compile
// definitions: an absolute path on every test's command line would make each test compilation of a clone in another
// folder miss the compiler cache, while this header is the same in every clone.
#pragma once

namespace ctid::test::paths {
extern const char* const examples_data;  ///< examples/data of the source tree
extern const char* const shared_data;    ///< ../shared/data beside the source tree (may be absent)
extern const char* const cli;            ///< the built ctid executable ("" when the apps are not built)
extern const char* const output;         ///< the CLI tests' folder in the build tree
}  // namespace ctid::test::paths

#define CTID_EXAMPLES_DATA_DIR ::ctid::test::paths::examples_data
#define CTID_SHARED_DATA_DIR ::ctid::test::paths::shared_data
#define CTID_CLI_PATH ::ctid::test::paths::cli
#define CTID_TEST_OUTPUT_DIR ::ctid::test::paths::output
