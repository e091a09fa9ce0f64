// WebAssembly exception handling in the threaded build (MM_WASM_THREADS only).
//
// Debian 12's Emscripten 3.1.6 pairs clang 14 with a libunwind whose landing-pad context
// (`__wasm_lpad_context`, the channel between compiler-generated landing pads and the C++
// personality function) is `thread_local`. Clang 14 still emits plain, non-TLS stores to that
// symbol (later clang versions emit TLS accesses), so in a -pthread link the landing pads write the
// landing-pad index and LSDA to one address and the personality function reads another: every
// exception is then caught only by `catch (...)` (measured: a thrown std::runtime_error skips
// `catch (const std::exception&)`), which breaks Spectra's cancel, the glTF parser's errors and
// every typed catch in the core.
//
// This file defines the context as the plain global the compiler expects, together with the
// small unwinder API around it, so the linker takes these definitions and never pulls libunwind's
// Unwind-wasm object. The context is then shared by all threads: two threads inside landing pads
// at the same instant would race. In this code base exceptions are thrown on the calling thread
// (cancel requests inside the eigensolver, parse errors) and pool tasks do not throw; a task that
// does (an allocation failure) is caught and rethrown on the calling thread by common/threads.cpp.
// The single-threaded build does not compile this file.
#include <cstdint>
#include <unwind.h>

#if !defined(__EMSCRIPTEN_PTHREADS__) || !defined(__wasm_exception_handling__)
#error "eh_threads.cpp belongs to the -pthread -fwasm-exceptions build only"
#endif

extern "C" {

// What the landing pads write (lpad_index, lsda) and read back (selector), in this order.
struct MmWasmLandingPadContext {
  std::uintptr_t lpad_index;
  std::uintptr_t lsda;
  std::uintptr_t selector;
};

MmWasmLandingPadContext __wasm_lpad_context;

_Unwind_Reason_Code __gxx_personality_wasm0(int version, _Unwind_Action actions, std::uint64_t exception_class,
                                            _Unwind_Exception* exception, _Unwind_Context* context);

// Called by every landing pad: wasm unwinds in the VM, so the personality function runs from here,
// in its cleanup phase only (there is no separate search phase).
_Unwind_Reason_Code _Unwind_CallPersonality(void* exception_ptr) {
  auto* exception = static_cast<_Unwind_Exception*>(exception_ptr);
  __wasm_lpad_context.selector = 0;
  return __gxx_personality_wasm0(1, _UA_CLEANUP_PHASE, exception->exception_class, exception,
                                 reinterpret_cast<_Unwind_Context*>(&__wasm_lpad_context));
}

// __cxa_throw: throw with the C++ tag (0).
_Unwind_Reason_Code _Unwind_RaiseException(_Unwind_Exception* exception) {
  __builtin_wasm_throw(0, exception);
}

// __cxa_end_catch on a foreign exception.
void _Unwind_DeleteException(_Unwind_Exception* exception) {
  if (exception->exception_cleanup) exception->exception_cleanup(_URC_FOREIGN_EXCEPTION_CAUGHT, exception);
}

// The personality function reports the matched handler through register 1 (the selector).
void _Unwind_SetGR(_Unwind_Context* context, int index, _Unwind_Word value) {
  if (index == 1) reinterpret_cast<MmWasmLandingPadContext*>(context)->selector = value;
}

// The call-site table is indexed by landing pad: the personality function subtracts 1 from the
// "IP" and uses it as a 1-based index, hence + 2.
_Unwind_Word _Unwind_GetIP(_Unwind_Context* context) {
  return reinterpret_cast<MmWasmLandingPadContext*>(context)->lpad_index + 2;
}

void _Unwind_SetIP(_Unwind_Context*, _Unwind_Word) {}

void* _Unwind_GetLanguageSpecificData(_Unwind_Context* context) {
  return reinterpret_cast<void*>(reinterpret_cast<MmWasmLandingPadContext*>(context)->lsda);
}

_Unwind_Ptr _Unwind_GetRegionStart(_Unwind_Context*) { return 0; }

}  // extern "C"
