// The Catch2 main of test_cli, compiled without -Werror (Catch2's own code
// trips GCC 12's -Wmaybe-uninitialized under the sanitizer build).
#define CATCH_CONFIG_MAIN
#include <catch2/catch.hpp>
