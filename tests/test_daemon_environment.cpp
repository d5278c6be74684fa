// The environment ctest gives these tests (tests/CMakeLists.txt, fgsr_test_env) reaches them and,
// through them, the fgsrd processes they start: Vulkan validation on, and in the sanitizer builds
// the sanitizers' options. For a long time only its first variable arrived (gtest_discover_tests
// split the list), so no test ran under validation and no sanitizer option applied, and nothing
// said so: this test does.
#include "raw_client.hpp"

#include <fgsr/testing/fgsrd_process.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <string>

namespace fgsr::test {
namespace {

std::string env(const char* name) {
    const char* v = std::getenv(name);
    return v ? v : "";
}

TEST(DaemonEnvironment, CtestRunsTheTestsAndTheirDaemonsUnderValidation) {
    // The list's first variable: a run outside ctest has none of them.
    if (env("FGSR_TEST_ENVIRONMENT") != "ctest") GTEST_SKIP() << "not started by ctest";
    EXPECT_EQ(env("FGSR_VALIDATION"), "1");
    EXPECT_NE(std::getenv("VK_LOADER_LAYERS_ENABLE"), nullptr);
#ifdef FGSR_TEST_ASAN
    EXPECT_NE(env("ASAN_OPTIONS").find("detect_leaks=1"), std::string::npos) << env("ASAN_OPTIONS");
    EXPECT_NE(env("LSAN_OPTIONS").find("lsan.supp"), std::string::npos) << env("LSAN_OPTIONS");
    EXPECT_NE(env("UBSAN_OPTIONS").find("halt_on_error=1"), std::string::npos) << env("UBSAN_OPTIONS");
#endif
#ifdef FGSR_TEST_TSAN
    EXPECT_NE(env("TSAN_OPTIONS").find("tsan.supp"), std::string::npos) << env("TSAN_OPTIONS");
#endif
    // A daemon started by a test has the validation layer loaded.
    auto d = FgsrdProcess::start();
    ASSERT_TRUE(d) << FgsrdProcess::last_error();
    const auto maps = d->mappings();
    EXPECT_TRUE(std::any_of(maps.begin(), maps.end(), [](const std::string& line) {
        return line.find("libVkLayer_khronos_validation") != std::string::npos;
    })) << "fgsrd runs without the Khronos validation layer";
}

} // namespace
} // namespace fgsr::test
