// The one guard every wasm entry point goes through (bind_*.cpp register functions with
// mm::wasm::bind<&f>("name") and session methods with guarded_method<&C::m>): a C++ exception that
// escapes a binding (a bug, or std::bad_alloc when the 4 GB heap is exhausted) becomes the page's
// error object {ok: false, code, message} instead of a trap that would take the worker down.
// Data errors are not exceptions: they come back from core as a Status and convert the same way
// (status_object in convert.h).
#pragma once

#include <new>
#include <string>
#include <type_traits>
#include <utility>

#include <emscripten/bind.h>
#include <emscripten/val.h>

#include "convert.h"

namespace mm::wasm {

namespace guard_detail {
template <class R>
R on_exception(const char* what, const std::exception* e, bool oom) {
  if constexpr (std::is_same_v<R, emscripten::val>) return exception_object(what, e, oom);
  else if constexpr (std::is_void_v<R>) return;
  else return R{};  // e.g. dispose → false
}
}  // namespace guard_detail

template <auto F>
struct Guarded;

template <class R, class... A, R (*F)(A...)>
struct Guarded<F> {
  static const char* name;
  static R call(A... args) {
    try {
      return F(std::forward<A>(args)...);
    } catch (const std::bad_alloc& e) {
      return guard_detail::on_exception<R>(name, &e, true);
    } catch (const std::exception& e) {
      return guard_detail::on_exception<R>(name, &e, false);
    } catch (...) {
      return guard_detail::on_exception<R>(name, nullptr, false);
    }
  }
};
template <class R, class... A, R (*F)(A...)>
const char* Guarded<F>::name = "binding";

// Registers free function F under `js_name`, guarded.
template <auto F>
void bind(const char* js_name) {
  Guarded<F>::name = js_name;
  emscripten::function(js_name, &Guarded<F>::call);
}

template <auto M>
struct GuardedMethod;

template <class C, class R, class... A, R (C::*M)(A...)>
struct GuardedMethod<M> {
  static R call(C& self, A... args) {
    try {
      return (self.*M)(std::forward<A>(args)...);
    } catch (const std::bad_alloc& e) {
      return guard_detail::on_exception<R>(C::kName, &e, true);
    } catch (const std::exception& e) {
      return guard_detail::on_exception<R>(C::kName, &e, false);
    } catch (...) {
      return guard_detail::on_exception<R>(C::kName, nullptr, false);
    }
  }
};

// A session method, guarded: class_<C>(...).function("drag", guarded_method<&C::drag>()).
// C::kName names the session in error messages.
template <auto M>
constexpr auto guarded_method() {
  return &GuardedMethod<M>::call;
}

}  // namespace mm::wasm
