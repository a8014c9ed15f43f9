// Driver for the GUI smoke tests (registered in tests/cmake/gui_smoke.cmake).
//
//   gui_smoke_check screenshot --app A --mesh M --layout L --out PNG [--width W --height H]
//                   [--expect-colors "r,g,b,min;..."] [-- app arguments...]
//     Runs `xvfb-run ... A --mesh M --layout L --screenshot PNG --frames 5 --quit` (no --frames
//     when the extra arguments contain --run; a fresh autosave folder PNG.autosave, so that no
//     autosave is offered over the scene) and checks the picture: expected size, the centre
//     differs from the background, it has edges (wireframe, arcs), and each expected colour
//     covers enough pixels. Exits 77 (CTest skip) when xvfb-run is not installed.
//   gui_smoke_check exit-code --app A --expect N [app arguments...]
//     Runs the app (no display needed when it fails before opening a window) and checks its
//     exit code.
#include <stb_image.h>  // implementation in Debian's libstb
#include <sys/wait.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace {

constexpr int kSkip = 77;

std::string quote(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

int run(const std::string& command) {
  std::printf("$ %s\n", command.c_str());
  std::fflush(stdout);
  const int status = std::system(command.c_str());
  if (status == -1 || !WIFEXITED(status)) return -1;
  return WEXITSTATUS(status);
}

bool on_path(const std::string& program) {
  return run("command -v " + program + " > /dev/null 2>&1") == 0;
}

// "r,g,b,min;r,g,b,min": colours (0-255) of which at least `min` pixels (each channel within
// 40) must appear right of the side panel.
struct ColorCheck {
  int r = 0, g = 0, b = 0, min = 0;
};
std::vector<ColorCheck> parse_colors(const std::string& text) {
  std::vector<ColorCheck> out;
  std::size_t start = 0;
  while (start < text.size()) {
    const std::size_t end = std::min(text.find(';', start), text.size());
    ColorCheck c;
    if (std::sscanf(text.substr(start, end - start).c_str(), "%d,%d,%d,%d", &c.r, &c.g, &c.b,
                    &c.min) == 4)
      out.push_back(c);
    start = end + 1;
  }
  return out;
}

int check_screenshot(const std::map<std::string, std::string>& args,
                     const std::vector<std::string>& rest) {
  if (!on_path("xvfb-run")) {
    std::printf("SKIPPED: xvfb-run is not installed (apt-get install xvfb xauth)\n");
    return kSkip;
  }
  const std::string png = args.at("--out");
  const int want_w = std::stoi(args.count("--width") ? args.at("--width") : "1280");
  const int want_h = std::stoi(args.count("--height") ? args.at("--height") : "800");
  for (const char* key : {"--mesh", "--layout"})
    if (!std::filesystem::exists(args.at(key))) {
      std::printf("FAIL: input %s is missing\n", args.at(key).c_str());
      return 1;
    }
  std::filesystem::remove(png);
  // A fresh autosave folder: an autosave left by another test would be offered in a window
  // over the scene.
  const std::string autosave = png + ".autosave";
  std::filesystem::remove_all(autosave);
  std::string command = "env QS_AUTOSAVE_DIR=" + quote(autosave) + " xvfb-run -a -s '-screen 0 " +
                        std::to_string(want_w) + "x" + std::to_string(want_h) + "x24' " +
                        quote(args.at("--app")) + " --mesh " + quote(args.at("--mesh")) +
                        " --layout " + quote(args.at("--layout")) + " --screenshot " + quote(png) +
                        " --quit";
  // Extra app arguments after "--"; a run takes its screenshot when it finishes.
  bool runs = false;
  for (const auto& a : rest) {
    command += " " + quote(a);
    runs = runs || a == "--run";
  }
  if (!runs) command += " --frames 5";
  const int code = run(command);
  if (code != 0) {
    std::printf("FAIL: quadsketch exited with %d\n", code);
    return 1;
  }
  int w = 0, h = 0, channels = 0;
  unsigned char* pixels = stbi_load(png.c_str(), &w, &h, &channels, 3);
  if (!pixels) {
    std::printf("FAIL: %s was not written or is not a PNG\n", png.c_str());
    return 1;
  }
  auto at = [&](int x, int y, int c) { return int(pixels[(std::size_t(y) * w + x) * 3 + c]); };
  auto luma = [&](int x, int y) {
    return (299 * at(x, y, 0) + 587 * at(x, y, 1) + 114 * at(x, y, 2)) / 1000;
  };
  int failures = 0;
  if (w != want_w || h != want_h) {
    std::printf("FAIL: size %dx%d, expected %dx%d\n", w, h, want_w, want_h);
    ++failures;
  }
  // Centre of the viewport: the scene is centred in the part right of the side panel. The
  // background is a vertical gradient, so compare each row with the background at the
  // right edge of the same row.
  const int x0 = w * 52 / 100, x1 = w * 74 / 100, y0 = h * 38 / 100, y1 = h * 62 / 100;
  int differing = 0, strong_gradients = 0, total = 0;
  for (int y = y0; y < y1; ++y) {
    const int bx = w - 4;
    for (int x = x0; x < x1; ++x, ++total) {
      int d = 0;
      for (int c = 0; c < 3; ++c) d = std::max(d, std::abs(at(x, y, c) - at(bx, y, c)));
      differing += d > 24;
      strong_gradients += std::abs(luma(x + 1, y) - luma(x, y)) > 40;
    }
  }
  const auto colors = parse_colors(args.count("--expect-colors") ? args.at("--expect-colors") : "");
  for (const auto& c : colors) {
    int found = 0;
    for (int y = 0; y < h; ++y)
      for (int x = w * 30 / 100; x < w; ++x)
        found += std::abs(at(x, y, 0) - c.r) <= 40 && std::abs(at(x, y, 1) - c.g) <= 40 &&
                 std::abs(at(x, y, 2) - c.b) <= 40;
    std::printf("colour (%d, %d, %d): %d pixels, expected at least %d\n", c.r, c.g, c.b, found,
                c.min);
    if (found < c.min) {
      std::printf("FAIL: too few pixels of colour (%d, %d, %d)\n", c.r, c.g, c.b);
      ++failures;
    }
  }
  stbi_image_free(pixels);
  std::printf("centre: %d of %d pixels differ from the background, %d strong gradients\n",
              differing, total, strong_gradients);
  if (differing < total / 2) {
    std::printf("FAIL: the centre looks like background (nothing drawn?)\n");
    ++failures;
  }
  if (strong_gradients < 200) {
    std::printf("FAIL: too few edges in the centre (wireframe/arcs missing?)\n");
    ++failures;
  }
  return failures ? 1 : 0;
}

int check_exit_code(const std::map<std::string, std::string>& args,
                    const std::vector<std::string>& rest) {
  std::string command = quote(args.at("--app"));
  for (const auto& a : rest) command += " " + quote(a);
  // Without a display the app must still fail cleanly on bad input (before any window).
  command = "env -u DISPLAY " + command;
  const int expect = std::stoi(args.at("--expect"));
  const int code = run(command);
  std::printf("exit code %d, expected %d\n", code, expect);
  return code == expect ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: gui_smoke_check screenshot|exit-code ...\n");
    return 2;
  }
  const std::string mode = argv[1];
  std::map<std::string, std::string> args;
  std::vector<std::string> rest;
  int i = 2;
  for (; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--") {
      ++i;
      break;
    }
    if (a.rfind("--", 0) == 0 && i + 1 < argc) args[a] = argv[++i];
  }
  for (; i < argc; ++i) rest.push_back(argv[i]);
  try {
    if (mode == "screenshot") return check_screenshot(args, rest);
    if (mode == "exit-code") return check_exit_code(args, rest);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "gui_smoke_check: %s (missing argument?)\n", e.what());
    return 2;
  }
  std::fprintf(stderr, "unknown mode %s\n", mode.c_str());
  return 2;
}
