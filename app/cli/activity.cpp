#include "app/cli/activity.h"

#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <new>
#include <utility>

#include "core/base/atomic_file.h"

namespace qs::cli {

namespace {

std::string& activity() {
  static std::string what = "starting";
  return what;
}

std::terminate_handler previous_terminate_handler = nullptr;

[[noreturn]] void on_terminate() {
  if (const std::exception_ptr e = std::current_exception()) {
    try {
      std::rethrow_exception(e);
    } catch (const std::bad_alloc&) {
      exit_out_of_memory();
    } catch (...) {
    }
  }
  if (previous_terminate_handler) previous_terminate_handler();
  std::abort();
}

}  // namespace

void set_activity(std::string what) {
  activity() = std::move(what);
}

const std::string& current_activity() {
  return activity();
}

std::string failure_message(const std::exception& e) {
  if (dynamic_cast<const std::bad_alloc*>(&e)) return "out of memory while " + activity();
  return e.what();
}

void exit_out_of_memory() {
  stop_atomic_writes_for_exit();
  std::cout.flush();
  std::fflush(stdout);
  // Streams a const char* and the existing string: nothing to allocate.
  std::cerr << "error: out of memory while " << activity() << std::endl;
  std::_Exit(1);
}

void handle_out_of_memory_in_terminate() {
  previous_terminate_handler = std::set_terminate(on_terminate);
}

}  // namespace qs::cli
