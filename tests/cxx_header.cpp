// cxx_header.cpp - polyc.h compiles as C++11 (-Wall -Wextra -Werror -pedantic)
// and links against the C library: names are not mangled, the structs are
// the same size on both sides, and a small map can be built from C++.
#include "polyc.h"

#include <cmath>
#include <cstdio>
#include <cstring>
#include <vector>

static int failures = 0;

static void check(bool ok, const char *what)
{
    if (!ok) {
        std::printf("cxx_header: FAIL: %s\n", what);
        failures++;
    }
}

int main()
{
    check(polyc_version() == POLYC_VERSION, "polyc_version() == POLYC_VERSION");
    check(polyc_struct_size("polyc_config") == sizeof(polyc_config), "sizeof polyc_config");
    check(polyc_struct_size("polyc_limits") == sizeof(polyc_limits), "sizeof polyc_limits");
    check(polyc_struct_size("polyc_scan") == sizeof(polyc_scan), "sizeof polyc_scan");
    check(polyc_struct_size("polyc_box") == sizeof(polyc_box), "sizeof polyc_box");
    check(polyc_struct_size("polyc_polyline") == sizeof(polyc_polyline), "sizeof polyc_polyline");
    check(polyc_struct_size("polyc_stats") == sizeof(polyc_stats), "sizeof polyc_stats");
    check(polyc_struct_size("polyc_iteration") == sizeof(polyc_iteration), "sizeof polyc_iteration");
    check(polyc_struct_size("polyc_occupancy_grid") == sizeof(polyc_occupancy_grid),
          "sizeof polyc_occupancy_grid");
    check(std::strcmp(polyc_status_str(POLYC_OK), "ok") == 0, "polyc_status_str");

    // one scan of a wall 2 m ahead, 1 to 3 m wide: at least one polyline
    polyc_config cfg;
    polyc_config_default(&cfg);
    std::vector<float> ranges(91);
    for (size_t i = 0; i < ranges.size(); i++) {
        double a = -0.785398 + 0.0174533 * static_cast<double>(i);
        ranges[i] = static_cast<float>(2.0 / std::cos(a));
    }
    polyc_scan scan = {0.0, 0.0, 0.0, -0.785398f, 0.0174533f, 0.02f, 30.0f,
                       static_cast<uint32_t>(ranges.size()), 0, ranges.data()};
    polyc_limits lim;
    check(polyc_limits_for_scans(&cfg, &scan, 1, &lim) == POLYC_OK, "polyc_limits_for_scans");
    size_t size = polyc_memory_size(&cfg, &lim);
    check(size > 0, "polyc_memory_size");
    std::vector<unsigned char> block(size);
    polyc_ctx *ctx = nullptr;
    check(polyc_init(block.data(), block.size(), &cfg, &lim, &ctx) == POLYC_OK, "polyc_init");
    check(polyc_add_scan(ctx, &scan) == POLYC_OK, "polyc_add_scan");
    check(polyc_build(ctx, nullptr, nullptr) == POLYC_OK, "polyc_build");
    check(polyc_polyline_count(ctx) >= 1, "at least one polyline");
    if (failures == 0)
        std::printf("cxx_header: ok (C++%ld, %u polylines)\n", static_cast<long>(__cplusplus / 100 % 100),
                    static_cast<unsigned>(polyc_polyline_count(ctx)));
    return failures ? 1 : 0;
}
