// Included by every bridge header: nothing thrown in C++ may unwind into Rust.
#pragma once
#include <exception>

// cxx turns std::exception into Err; anything else thrown must not cross into Rust either.
namespace rust {
namespace behavior {
template <typename Try, typename Fail>
static void trycatch(Try&& func, Fail&& fail) noexcept try {
    func();
} catch (const std::exception& e) {
    fail(e.what());
} catch (...) {
    fail("unknown C++ exception");
}
}  // namespace behavior
}  // namespace rust
