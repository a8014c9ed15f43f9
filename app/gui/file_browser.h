// The in-app file browser's model (GL-free; drawn by panel_file_browser.cpp): a folder listing
// with its subfolders first and the files that pass the extension filter, a file name, and
// the path the user chose.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace qs::app {

enum class BrowserMode {
  Open,  //!< a mesh or a layout (by extension)
  Save,  //!< a layout file name (created or replaced)
};

struct BrowserEntry {
  std::string name;
  bool directory = false;
  std::uintmax_t size = 0;  //!< bytes (files)
};

//! An extension filter: the label shown and the lower-case extensions it lets through
//! (empty: every file).
struct BrowserFilter {
  std::string label;
  std::vector<std::string> extensions;
};

class FileBrowser {
 public:
  //! Shows the browser in \p mode at the folder of \p start (a file or a folder; the home
  //! folder when empty or missing). In Save mode the file name starts as \p start's name.
  void open(BrowserMode mode, const std::string& start);
  void close() { open_ = false; }
  bool is_open() const { return open_; }
  BrowserMode mode() const { return mode_; }

  //! The filters of the mode (Open: meshes and layouts, meshes, layouts, all files; Save:
  //! layouts, all files).
  const std::vector<BrowserFilter>& filters() const;
  int filter() const { return filter_; }
  void set_filter(int index);

  //! Lists \p folder; false (the listing unchanged, error() set) when it cannot be read.
  bool navigate(const std::string& folder);
  bool up();
  //! Re-reads the current folder.
  void refresh();
  const std::string& folder() const { return folder_; }
  const std::vector<BrowserEntry>& entries() const { return entries_; }
  const std::string& error() const { return error_; }
  bool show_hidden = false;

  //! The file name field (typed into by the UI).
  std::string file_name;
  //! Sets the file name from outside the field (a click on a file, a script); bumps
  //! name_version so that the UI's field shows it even while it has the keyboard.
  void set_file_name(const std::string& name);
  int name_version() const { return name_version_; }
  //! The folder field (set to folder() by every navigation; typed paths go to navigate()).
  std::string folder_field;
  //! Save mode: the existing file the user is asked to confirm replacing ("" when none).
  std::string confirm_replace;
  //! Clicking an entry: a folder is entered, a file name goes to the field.
  void select(const BrowserEntry& entry);
  //! The full path of the file name field (a relative name is taken in the current folder);
  //! "" when the field is empty. In Save mode ".layout.json" is added to a name without an
  //! extension.
  std::string chosen_path() const;

 private:
  bool passes(const std::string& name) const;
  bool open_ = false;
  BrowserMode mode_ = BrowserMode::Open;
  int filter_ = 0;
  std::string folder_;
  std::vector<BrowserEntry> entries_;
  std::string error_;
  int name_version_ = 0;
};

//! The user's home folder ($HOME), or the working directory.
std::string home_folder();

}  // namespace qs::app
