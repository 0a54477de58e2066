// Test fixtures with a current headless GL context, or the test skipped where the machine has
// none: HeadlessTest runs once per backend (EGL surfaceless, OSMesa); EglTest<Size> on EGL alone.
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

template <int Size = 64, class Base = ::testing::Test>
class EglTest : public Base {
protected:
    void SetUp() override {
        try {
            context_ = createHeadlessContext(Backend::Egl, Size, Size);
        } catch (const ContextError& e) {
            GTEST_SKIP() << "no EGL context: " << e.what();
        }
    }
    std::unique_ptr<HeadlessContext> context_;
};

}  // namespace shrefract::test
