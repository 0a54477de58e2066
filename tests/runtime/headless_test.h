// A test fixture per headless backend (EGL surfaceless, OSMesa): a current context, or the test
// skipped where the machine has none.
#pragma once

#include <gtest/gtest.h>

#include <memory>

#include "shrefract/context.h"

namespace shrefract::test {

class HeadlessTest : public ::testing::TestWithParam<Backend> {
protected:
    void SetUp() override {
        try {
            context_ = createHeadlessContext(GetParam(), 64, 64);
        } catch (const ContextError& e) {
            GTEST_SKIP() << "no " << nameOf(GetParam()) << " context: " << e.what();
        }
    }
    std::unique_ptr<HeadlessContext> context_;
};

}  // namespace shrefract::test
