// pdt benchmark helper: CGAL's Delaunay_triangulation_2 on a pdt point file
// ("x y" per line).  Compiled at bench time into build/bench/ by
// scripts/bench/10-triangulate.sh.  Prints one JSON line: points, finite
// faces, and the seconds spent reading and building (insert of the whole
// range, which spatially sorts first -- CGAL's fast path).
#include <CGAL/Delaunay_triangulation_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <vector>

typedef CGAL::Exact_predicates_inexact_constructions_kernel K;
typedef CGAL::Delaunay_triangulation_2<K> DT;

static double now()
{
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch())
        .count();
}

int main(int argc, char **argv)
{
    if (argc != 2) {
        std::fprintf(stderr, "usage: cgal_dt POINTS\n");
        return 2;
    }
    double t0 = now();
    std::FILE *f = std::fopen(argv[1], "rb");
    if (!f) {
        std::perror(argv[1]);
        return 2;
    }
    std::vector<K::Point_2> pts;
    long x, y;
    while (std::fscanf(f, "%ld %ld", &x, &y) == 2) pts.emplace_back((double)x, (double)y);
    std::fclose(f);
    double t1 = now();
    DT dt;
    dt.insert(pts.begin(), pts.end());
    double t2 = now();
    std::printf("{\"tool\": \"cgal\", \"n\": %zu, \"faces\": %zu, \"read\": %.6f, \"build\": %.6f}\n",
                pts.size(), (size_t)dt.number_of_faces(), t1 - t0, t2 - t1);
    return 0;
}
