// quadsketch: the layout editor (interfaces.md §3).
#include <CLI/CLI.hpp>

#include "app/gui/app.h"

int main(int argc, char** argv) {
  qs::app::AppOptions options;
  CLI::App cli("QuadSketch: sketch a quad layout on a triangle mesh and optimize it.");
  cli.add_option("--mesh", options.mesh_path, "Triangle mesh (.obj .off .ply .stl)");
  cli.add_option("--layout", options.layout_path, "Layout (.layout.json)");
  cli.add_flag("--run", options.run, "Start the optimization at once");
  cli.add_option("--screenshot", options.screenshot_path,
                 "Save the window as PNG after the run finishes (or after --frames frames)");
  cli.add_option("--frames", options.frames, "Number of frames before the screenshot / quit")
      ->check(CLI::PositiveNumber);
  cli.add_flag("--quit", options.quit, "Exit after the screenshot");
  cli.add_option("--width", options.width, "Window width")->check(CLI::Range(200, 8192));
  cli.add_option("--height", options.height, "Window height")->check(CLI::Range(200, 8192));
  CLI11_PARSE(cli, argc, argv);
  qs::app::App app(std::move(options));
  return app.run();
}
