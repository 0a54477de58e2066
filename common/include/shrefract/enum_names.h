// One table per enumeration, read both ways: nameOf(value) for output, parseName<E>(text) for the
// command lines and files that spell values as words. An enumeration declares its table once,
// next to itself:
//
//   enum class Shading { Jitter, Spread };
//   template <> struct EnumNames<Shading> {
//       static constexpr const char* what = "shading";
//       static constexpr NamedValue<Shading> table[] = {{Shading::Jitter, "jitter"}, ...};
//   };
//
// Header-only and dependency-free: installed with the runtime's headers, used by every layer.
#pragma once

#include <stdexcept>
#include <string>
#include <string_view>

namespace shrefract {

template <class E>
struct NamedValue {
    E value;
    const char* name;
};

template <class E>
struct EnumNames;  // specialised per enumeration: `what` and `table`

// The value's name; "?" for a value outside the table (a cast from an integer).
template <class E>
const char* nameOf(E value) {
    for (const NamedValue<E>& v : EnumNames<E>::table)
        if (v.value == value) return v.name;
    return "?";
}

// Every name, "a | b | c", for help texts and error messages.
template <class E>
std::string allNames() {
    std::string out;
    for (const NamedValue<E>& v : EnumNames<E>::table) out += (out.empty() ? "" : " | ") + std::string(v.name);
    return out;
}

// The value named `text`; std::invalid_argument naming the choices otherwise.
template <class E>
E parseName(std::string_view text) {
    for (const NamedValue<E>& v : EnumNames<E>::table)
        if (text == v.name) return v.value;
    throw std::invalid_argument("unknown " + std::string(EnumNames<E>::what) + " '" +
                                std::string(text) + "' (" + allNames<E>() + ")");
}

}  // namespace shrefract
