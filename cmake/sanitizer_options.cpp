// Default runtime options of AddressSanitizer, LeakSanitizer and UndefinedBehaviorSanitizer for
// every executable of a COSTAR_SANITIZE=ON build (tests and the costar CLI): a run needs no
// environment variables, and ASAN_OPTIONS / UBSAN_OPTIONS / LSAN_OPTIONS still override them.

extern "C" {

__attribute__((visibility("default"), used)) const char* __asan_default_options() {
  // Leaks are checked (detect_leaks=1); reports fail the process.
  return "detect_leaks=1:strict_string_checks=1:check_initialization_order=1:detect_stack_use_after_return=1";
}

__attribute__((visibility("default"), used)) const char* __ubsan_default_options() {
  return "print_stacktrace=1:halt_on_error=1";
}

// Leak suppressions: third-party code only, never costar's.
__attribute__((visibility("default"), used)) const char* __lsan_default_suppressions() { return ""; }

}  // extern "C"
