// Helpers shared by the fuzz targets: the readers take file paths, so inputs go through a
// per-process temporary file (in /dev/shm when available).
#pragma once

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <string>

#include "core/base/errors.h"

namespace qs::fuzz {

//! Path of this process's temporary input file with extension \p ext (".obj", ...).
inline std::string temp_path(const std::string& ext) {
  namespace fs = std::filesystem;
  static const fs::path dir = [] {
    std::error_code ec;
    if (fs::is_directory("/dev/shm", ec)) return fs::path("/dev/shm");
    return fs::temp_directory_path();
  }();
  return (dir / ("qs_fuzz_" + std::to_string(getpid()) + ext)).string();
}

//! Writes \p data to temp_path(ext) and returns the path.
inline std::string write_temp(const std::uint8_t* data, std::size_t size, const std::string& ext) {
  const std::string path = temp_path(ext);
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  out.close();
  if (!out) {
    std::fprintf(stderr, "fuzz: cannot write %s\n", path.c_str());
    std::abort();
  }
  return path;
}

//! Runs \p f; InvalidInputError is the expected way to refuse an input. Any other exception
//! is a finding (the CLI would exit with code 1 or 3 instead of 2): abort so libFuzzer saves it.
template <typename F>
void expect_clean(const char* what, F&& f) {
  try {
    f();
  } catch (const InvalidInputError&) {
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fuzz: %s threw a non-input error: %s\n", what, e.what());
    std::abort();
  }
}

}  // namespace qs::fuzz
