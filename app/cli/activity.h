// What quadsketch-cli is doing, for the message of a failure that does not say it itself: an
// allocation failure (std::bad_alloc) becomes "out of memory while <activity>", wherever it is
// thrown (also in a destructor or another thread, which end in std::terminate).
#pragma once

#include <exception>
#include <string>

namespace qs::cli {

//! Records what the command does from now on, e.g. "loading the mesh 'bunny.obj'" (a phrase
//! that follows "while"). Called by the main thread only.
void set_activity(std::string what);

//! The phrase of the last set_activity call ("starting" before any).
const std::string& current_activity();

//! The message for an error that ends a command: "out of memory while <activity>" for
//! std::bad_alloc, else e.what().
std::string failure_message(const std::exception& e);

//! Ends the process after an allocation failure: removes the temporary files of unfinished
//! atomic writes, flushes stdout, prints "error: out of memory while <activity>" to stderr and
//! exits with code 1 without running exit handlers (a library thread that could not get its
//! memory may never finish, and exit() would wait for it).
[[noreturn]] void exit_out_of_memory();

//! Makes std::terminate call exit_out_of_memory when the exception that caused it is a
//! std::bad_alloc (thrown in a destructor during unwinding, in a noexcept function or in
//! another thread); other causes keep the default behaviour.
void handle_out_of_memory_in_terminate();

}  // namespace qs::cli
