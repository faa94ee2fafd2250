// Prints a case's layout as JSON (see SheetMetalLayout::to_json), for plot_layout.py.
// Usage: twincal_export_layout body|door
#include <cstdio>
#include <string_view>

#include "twincal/sheet_metal/sheet_metal_layout.hpp"

int main(int argc, char** argv) {
  const std::string_view which = argc == 2 ? argv[1] : "";
  if (which != "body" && which != "door") {
    std::fprintf(stderr, "usage: twincal_export_layout body|door\n");
    return 2;
  }
  const twincal::SheetMetalLayout layout =
      which == "body" ? twincal::SheetMetalLayout::body() : twincal::SheetMetalLayout::door();
  std::printf("%s\n", layout.to_json().c_str());
  return 0;
}
