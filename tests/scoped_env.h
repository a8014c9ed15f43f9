// Test helpers for code that reads the environment (the editor's HOME, XDG_CONFIG_HOME and
// QS_AUTOSAVE_DIR): an environment variable set for a scope, and a temporary folder holding a
// test's own home, config and autosave folders.
#pragma once

#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <optional>
#include <string>
#include <system_error>

namespace qs::test {

//! Sets environment variable \p name to \p value until destroyed, then restores its old value
//! (or unsets it when it had none).
class ScopedEnv {
 public:
  ScopedEnv(const char* name, const std::string& value) : name_(name) {
    if (const char* old = std::getenv(name)) old_ = old;
    setenv(name, value.c_str(), 1);
  }
  ~ScopedEnv() {
    if (old_)
      setenv(name_, old_->c_str(), 1);
    else
      unsetenv(name_);
  }
  ScopedEnv(const ScopedEnv&) = delete;
  ScopedEnv& operator=(const ScopedEnv&) = delete;

 private:
  const char* name_;
  std::optional<std::string> old_;
};

//! A folder `<tmp>/<prefix>_<pid>_<name>` with `home/` (HOME), `config/` (XDG_CONFIG_HOME) and
//! `autosave/` (QS_AUTOSAVE_DIR) for the editor under test; removed with everything in it when
//! destroyed.
class EditorSandbox {
 public:
  EditorSandbox(const std::string& prefix, const std::string& name)
      : dir_(std::filesystem::temp_directory_path() /
             (prefix + "_" + std::to_string(::getpid()) + "_" + name)),
        home_("HOME", (dir_ / "home").string()),
        config_("XDG_CONFIG_HOME", (dir_ / "config").string()),
        autosave_("QS_AUTOSAVE_DIR", (dir_ / "autosave").string()) {
    std::filesystem::create_directories(dir_ / "home");
  }
  ~EditorSandbox() {
    std::error_code ec;
    std::filesystem::remove_all(dir_, ec);
  }
  const std::filesystem::path& dir() const { return dir_; }

 private:
  std::filesystem::path dir_;
  ScopedEnv home_, config_, autosave_;
};

}  // namespace qs::test
