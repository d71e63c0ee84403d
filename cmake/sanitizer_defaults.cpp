// Linked into every executable of a BACKLASH_SANITIZE build (see the top-level
// CMakeLists.txt): the sanitizer runtimes read these defaults before the
// environment, so test discovery, build-time generators and the CLI behave the
// same whether or not ASAN_OPTIONS / UBSAN_OPTIONS are set.  The environment
// still overrides them.
//   detect_leaks=0  GiNaC/CLN keep static-lifetime allocations that LeakSanitizer
//                   reports at exit; those reports would fail every run.
//   halt_on_error   UBSan findings are fatal (with -fno-sanitize-recover=undefined).

extern "C" __attribute__((visibility("default"), used)) const char* __asan_default_options() {
  return "detect_leaks=0";
}

extern "C" __attribute__((visibility("default"), used)) const char* __ubsan_default_options() {
  return "print_stacktrace=1:halt_on_error=1";
}
