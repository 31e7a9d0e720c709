#include <t_junctions.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <utility>
#include <vector>

#include <scene_centring.h>

namespace {

enum class Kind { kTriangle, kQuad, kRect };

// A flat primitive while splitting: its corners as written (doubles) and as rendered (moved to
// the scene's centre and rounded once).
struct Piece {
    Kind kind = Kind::kTriangle;
    int corners = 3;
    WrittenPoint written[4];
    Vec3 rendered[4];
    int material = 0;
    int axis = -1;  // a rectangle's plane axis
};

// A vertex of some piece: the point that may lie on another piece's edge.
struct Point {
    Vec3 rendered;
    WrittenPoint written;
    bool of_rect;
};

double coordinate(const WrittenPoint& p, int axis) {
    return axis == 0 ? p.x : (axis == 1 ? p.y : p.z);
}
void set_coordinate(WrittenPoint& p, int axis, double value) {
    (axis == 0 ? p.x : (axis == 1 ? p.y : p.z)) = value;
}
Vec3 rounded(const WrittenPoint& p) {
    return {static_cast<real>(p.x), static_cast<real>(p.y), static_cast<real>(p.z)};
}
bool same(Vec3 a, Vec3 b) { return a.x == b.x && a.y == b.y && a.z == b.z; }
Vec3 lower(Vec3 a, Vec3 b) {
    return {min_float(a.x, b.x), min_float(a.y, b.y), min_float(a.z, b.z)};
}
Vec3 upper(Vec3 a, Vec3 b) {
    return {max_float(a.x, b.x), max_float(a.y, b.y), max_float(a.z, b.z)};
}

// Whether a triangle has no area as rendered: it is never hit, so nothing meets it.
bool flat(const Piece& p) {
    if (p.kind != Kind::kTriangle) return false;
    long double e1[3], e2[3];
    for (int i = 0; i < 3; ++i) {
        e1[i] = static_cast<long double>(p.rendered[1][i]) - p.rendered[0][i];
        e2[i] = static_cast<long double>(p.rendered[2][i]) - p.rendered[0][i];
    }
    return e1[1] * e2[2] == e1[2] * e2[1] && e1[2] * e2[0] == e1[0] * e2[2] &&
           e1[0] * e2[1] == e1[1] * e2[0];
}

// Rounding moves each centred coordinate by half an ulp, so a point written on an edge lies
// within about 2 ulps of the rendered edge's line; computing the distance in long double adds
// a few more in the double build where long double is double. 8 ulps of the largest
// coordinate covers both.
constexpr long double kCollinearUlps = 8;

// Where p lies on the edge a-b, strictly between its ends and collinear within rounding: its
// position along the edge in (0, 1), else -1. In long double on the rendered points.
long double along_edge(Vec3 a, Vec3 b, Vec3 p) {
    if (same(p, a) || same(p, b)) return -1;
    long double d[3], e[3], dd = 0, ed = 0, extent = 0;
    for (int i = 0; i < 3; ++i) {
        d[i] = static_cast<long double>(b[i]) - a[i];
        e[i] = static_cast<long double>(p[i]) - a[i];
        dd += d[i] * d[i];
        ed += e[i] * d[i];
        extent = std::max({extent, std::fabs(static_cast<long double>(a[i])),
                           std::fabs(static_cast<long double>(b[i])),
                           std::fabs(static_cast<long double>(p[i]))});
    }
    const long double t = ed / dd;
    if (!(t > 0 && t < 1)) return -1;
    const long double c[3] = {e[1] * d[2] - e[2] * d[1], e[2] * d[0] - e[0] * d[2],
                              e[0] * d[1] - e[1] * d[0]};
    const long double tolerance = kCollinearUlps * kRealEpsilon * extent;
    const long double distance_squared = (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]) / dd;
    return distance_squared <= tolerance * tolerance ? t : -1;
}

// The scene's vertices in a uniform grid over their bounds (2 cbrt(n) cells a side), so an edge
// looks only at those in the cells its bounding box covers, whatever the mesh's orientation
// (a list sorted on one axis would be quadratic for a mesh in a plane x = c).
class PointIndex {
public:
    explicit PointIndex(const std::vector<Piece>& pieces) {
        std::vector<Point> points;
        for (const Piece& piece : pieces) {
            if (flat(piece)) continue;
            for (int k = 0; k < piece.corners; ++k)
                points.push_back({piece.rendered[k], piece.written[k], piece.kind == Kind::kRect});
        }
        if (points.empty()) return;
        // Each rendered point once; it is a rectangle's only if no other kind has it.
        const auto less = [](const Point& a, const Point& b) {
            return std::array<real, 3>{a.rendered.x, a.rendered.y, a.rendered.z} <
                   std::array<real, 3>{b.rendered.x, b.rendered.y, b.rendered.z};
        };
        std::sort(points.begin(), points.end(), less);
        size_t kept = 0;
        for (size_t i = 0; i < points.size(); ++i) {
            if (kept > 0 && same(points[kept - 1].rendered, points[i].rendered))
                points[kept - 1].of_rect = points[kept - 1].of_rect && points[i].of_rect;
            else points[kept++] = points[i];
        }
        points.resize(kept);
        for (int axis = 0; axis < 3; ++axis) {
            lo_[axis] = hi_[axis] = points[0].rendered[axis];
            for (const Point& p : points) {
                lo_[axis] = std::min(lo_[axis], double(p.rendered[axis]));
                hi_[axis] = std::max(hi_[axis], double(p.rendered[axis]));
            }
        }
        side_ = std::max(1, std::min(128, static_cast<int>(2 * std::cbrt(double(points.size())))));
        // Counting sort by cell: start_[c] .. start_[c + 1] are cell c's points.
        start_.assign(size_t(side_) * side_ * side_ + 1, 0);
        for (const Point& p : points) ++start_[cell_of(p.rendered) + 1];
        for (size_t c = 1; c < start_.size(); ++c) start_[c] += start_[c - 1];
        std::vector<size_t> fill(start_.begin(), start_.end() - 1);
        points_.resize(points.size());
        for (const Point& p : points) points_[fill[cell_of(p.rendered)]++] = p;
    }

    // Calls visit(point) for every vertex (and perhaps a few more) within margin of the box
    // with corners a and b.
    template <typename Visit>
    void near_box(Vec3 a, Vec3 b, double margin, Visit visit) const {
        if (points_.empty()) return;
        int from[3], to[3];
        for (int axis = 0; axis < 3; ++axis) {
            from[axis] = cell(axis, std::min(double(a[axis]), double(b[axis])) - margin);
            to[axis] = cell(axis, std::max(double(a[axis]), double(b[axis])) + margin);
        }
        for (int i = from[0]; i <= to[0]; ++i) {
            for (int j = from[1]; j <= to[1]; ++j) {
                for (int k = from[2]; k <= to[2]; ++k) {
                    const size_t c = (size_t(i) * side_ + j) * side_ + k;
                    for (size_t n = start_[c]; n < start_[c + 1]; ++n) visit(points_[n]);
                }
            }
        }
    }

private:
    // Monotonic in x, so a point within a range lies in the cells of the range's ends.
    int cell(int axis, double x) const {
        const double extent = hi_[axis] - lo_[axis];
        if (!(extent > 0)) return 0;
        const double at = (x - lo_[axis]) / extent * side_;
        return at <= 0 ? 0 : (at >= side_ - 1 ? side_ - 1 : static_cast<int>(at));
    }
    size_t cell_of(Vec3 p) const {
        return (size_t(cell(0, p.x)) * side_ + cell(1, p.y)) * side_ + cell(2, p.z);
    }

    double lo_[3] = {0, 0, 0}, hi_[3] = {0, 0, 0};
    int side_ = 1;
    std::vector<size_t> start_;
    std::vector<Point> points_;
};

// A point found on an edge, by its position along the edge.
struct OnEdge {
    long double t;
    Point point;
};

// The points of `index` on the edge a-b of a triangle or convex quad, in order from a, each
// rendered point once.
std::vector<OnEdge> points_on_edge(const PointIndex& index, Vec3 a, Vec3 b) {
    const double extent = std::max(max_component(abs(a)), max_component(abs(b)));
    const double margin = 4 * kCollinearUlps * kRealEpsilon * extent;
    std::vector<OnEdge> found;
    index.near_box(a, b, margin, [&](const Point& p) {
        for (int axis = 0; axis < 3; ++axis) {  // the edge's box first: most points are far
            const double c = p.rendered[axis];
            if (c < std::min(a[axis], b[axis]) - margin || c > std::max(a[axis], b[axis]) + margin)
                return;
        }
        const long double t = along_edge(a, b, p.rendered);
        if (t > 0) found.push_back({t, p});
    });
    std::sort(found.begin(), found.end(),
              [](const OnEdge& x, const OnEdge& y) { return x.t < y.t; });
    found.erase(std::unique(found.begin(), found.end(),
                            [](const OnEdge& x, const OnEdge& y) {
                                return same(x.point.rendered, y.point.rendered);
                            }),
                found.end());
    return found;
}

// The triangle or convex quad as a fan of triangles around its centroid, its boundary passing
// through every point found on its edges; empty when none is.
std::vector<Piece> fan(const Piece& piece, const PointIndex& index, const WrittenPoint& centre) {
    std::vector<Point> boundary;
    bool split = false;
    for (int k = 0; k < piece.corners; ++k) {
        const int next = (k + 1) % piece.corners;
        boundary.push_back({piece.rendered[k], piece.written[k], false});
        for (const OnEdge& on : points_on_edge(index, piece.rendered[k], piece.rendered[next])) {
            // A sliver's own corner can lie within the tolerance of its opposite edge: splitting
            // there made slivers like it, pass after pass, until memory ran out.
            bool own = false;
            for (int c = 0; c < piece.corners; ++c)
                own = own || same(on.point.rendered, piece.rendered[c]);
            if (own) continue;
            boundary.push_back(on.point);
            split = true;
        }
    }
    if (!split) return {};
    // The mean of the written corners, kept within their range on each axis (so a piece in
    // the plane x = c keeps its centroid there exactly).
    WrittenPoint centroid;
    for (int axis = 0; axis < 3; ++axis) {
        double sum = 0, lo = coordinate(piece.written[0], axis), hi = lo;
        for (int k = 0; k < piece.corners; ++k) {
            const double c = coordinate(piece.written[k], axis);
            sum += c;
            lo = std::min(lo, c);
            hi = std::max(hi, c);
        }
        set_coordinate(centroid, axis, std::clamp(sum / piece.corners, lo, hi));
    }
    const Vec3 centroid_rendered = moved_to_centre(centroid, centre);
    std::vector<Piece> pieces;
    for (size_t k = 0; k < boundary.size(); ++k) {
        const Point& from = boundary[k];
        const Point& to = boundary[(k + 1) % boundary.size()];
        Piece t;
        t.kind = Kind::kTriangle;
        t.corners = 3;
        t.material = piece.material;
        t.written[0] = centroid, t.rendered[0] = centroid_rendered;
        t.written[1] = from.written, t.rendered[1] = from.rendered;
        t.written[2] = to.written, t.rendered[2] = to.rendered;
        pieces.push_back(t);  // counter-clockwise as the piece's boundary is
    }
    return pieces;
}

// A cut across a rectangle: the rendered coordinate, and the written one it rounds from.
struct Cut {
    real rendered;
    double written;
};

// The rectangle cut across at every vertex of a triangle or convex quad that lies exactly on
// one of its edges, strictly between the ends: a grid of smaller rectangles with the same
// winding; empty when there is none.
std::vector<Piece> cut(const Piece& rect, const PointIndex& index) {
    const int in_plane[2] = {rect_axis_u(rect.axis), rect_axis_v(rect.axis)};
    std::vector<Cut> cuts[2];
    for (int k = 0; k < 4; ++k) {
        const Vec3 a = rect.rendered[k], b = rect.rendered[(k + 1) % 4];
        const int along = a[in_plane[0]] != b[in_plane[0]] ? 0 : 1;
        const int axis = in_plane[along], fixed = in_plane[1 - along];
        const real lo = min_float(a[axis], b[axis]), hi = max_float(a[axis], b[axis]);
        index.near_box(a, b, 0.0, [&](const Point& p) {
            const Vec3 q = p.rendered;
            if (!p.of_rect && q[rect.axis] == a[rect.axis] && q[fixed] == a[fixed] &&
                q[axis] > lo && q[axis] < hi)
                cuts[along].push_back({q[axis], coordinate(p.written, axis)});
        });
    }
    if (cuts[0].empty() && cuts[1].empty()) return {};
    real lo[2], hi[2];
    for (int d = 0; d < 2; ++d) {
        std::sort(cuts[d].begin(), cuts[d].end(),
                  [](const Cut& x, const Cut& y) { return x.rendered < y.rendered; });
        cuts[d].erase(
            std::unique(cuts[d].begin(), cuts[d].end(),
                        [](const Cut& x, const Cut& y) { return x.rendered == y.rendered; }),
            cuts[d].end());
        lo[d] = hi[d] = rect.rendered[0][in_plane[d]];
        for (const Vec3& c : rect.rendered) {
            lo[d] = min_float(lo[d], c[in_plane[d]]);
            hi[d] = max_float(hi[d], c[in_plane[d]]);
        }
    }
    // Each corner keeps its own written coordinates, but for the in-plane ones a cut replaces:
    // the strip [i, i+1] of cuts on each axis, where 0 and cuts.size() + 1 are the
    // rectangle's own sides. Corners keep their order, so the winding stays.
    std::vector<Piece> pieces;
    for (size_t i = 0; i <= cuts[0].size(); ++i) {
        for (size_t j = 0; j <= cuts[1].size(); ++j) {
            const size_t strip[2] = {i, j};
            Piece r = rect;
            for (int k = 0; k < 4; ++k) {
                for (int d = 0; d < 2; ++d) {
                    const bool high = rect.rendered[k][in_plane[d]] == hi[d];
                    const size_t side = strip[d] + (high ? 1 : 0);  // index into lo, cuts, hi
                    if (side == 0 || side == cuts[d].size() + 1) continue;  // its own side
                    set_coordinate(r.written[k], in_plane[d], cuts[d][side - 1].written);
                }
            }
            pieces.push_back(r);
        }
    }
    return pieces;
}

// An edge as two points, the lesser first: the same key from either side.
using EdgeKey = std::array<real, 6>;
EdgeKey edge_key(Vec3 p, Vec3 q) {
    EdgeKey a{p.x, p.y, p.z, q.x, q.y, q.z}, b{q.x, q.y, q.z, p.x, p.y, p.z};
    return a < b ? a : b;
}
EdgeKey edge_of(const Vec3* corners, int count, int k) {
    return edge_key(corners[k], corners[(k + 1) % count]);
}

// One edge of one primitive or piece; sorted by key, the holders of an edge come together.
struct EdgeUse {
    EdgeKey key;
    size_t holder;
    int edge;
    bool operator<(const EdgeUse& o) const { return key < o.key; }
};

// classify_quads's rule on the pieces: a rectangle that shares an edge with a triangle or a
// convex quad becomes a convex quad, and so in turn does every rectangle sharing an edge with
// it. Returns how many it changed.
int demote_rects(std::vector<Piece>& pieces) {
    std::vector<EdgeKey> shared;
    std::map<EdgeKey, std::vector<size_t>> rect_edges;
    const auto edges = [](const Piece& p, int k) {
        return edge_key(p.rendered[k], p.rendered[(k + 1) % p.corners]);
    };
    for (size_t i = 0; i < pieces.size(); ++i) {
        for (int k = 0; k < pieces[i].corners; ++k) {
            if (pieces[i].kind == Kind::kRect) rect_edges[edges(pieces[i], k)].push_back(i);
            else shared.push_back(edges(pieces[i], k));
        }
    }
    int demoted = 0;
    while (!shared.empty()) {  // a worklist: each rectangle is demoted once
        const auto found = rect_edges.find(shared.back());
        shared.pop_back();
        if (found == rect_edges.end()) continue;
        for (size_t i : found->second) {
            if (pieces[i].kind != Kind::kRect) continue;
            pieces[i].kind = Kind::kQuad;
            ++demoted;
            for (int k = 0; k < 4; ++k) shared.push_back(edges(pieces[i], k));
        }
    }
    return demoted;
}

// ---- Edges that end inside faces ------------------------------------------------------------
// A primitive's edge can lie in another's plane and run across its interior (a ceiling whose
// edges lie inside walls that rise past it): no vertex lies on an edge there, so the splitting
// above finds nothing, and a ray through the joint can pass between the ceiling and the wall
// (the wall's face has no edge there for the watertight test to share). Such a face is cut
// in two along the edge's line, from boundary to boundary; the edge's ends then lie on the
// cut, and the splitting at T-junctions makes both share it end to end.

// A piece's plane as rendered, and its corners in the two coordinates that remain when the
// normal's largest axis is dropped, with the sign that makes the boundary counter-clockwise.
struct FacePlane {
    long double normal[3] = {0, 0, 0};
    long double offset = 0;
    long double extent = 0;  // largest |coordinate| of its corners
    int u = 0, v = 1;  // the in-plane axes
    long double orientation = 1;
    bool ok = false;
};

FacePlane face_plane(const Piece& p) {
    FacePlane f;
    long double a[3], b[3];
    for (int i = 0; i < 3; ++i) {
        const long double r0 = p.rendered[0][i];
        if (p.corners == 3) {
            a[i] = static_cast<long double>(p.rendered[1][i]) - r0;
            b[i] = static_cast<long double>(p.rendered[2][i]) - r0;
        } else {  // the diagonals
            a[i] = static_cast<long double>(p.rendered[2][i]) - r0;
            b[i] = static_cast<long double>(p.rendered[3][i]) - p.rendered[1][i];
        }
    }
    long double n[3] = {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2],
                        a[0] * b[1] - a[1] * b[0]};
    const long double length = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (!(length > 0)) return f;
    int drop = 0;
    for (int i = 0; i < 3; ++i) {
        f.normal[i] = n[i] / length;
        if (std::fabs(f.normal[i]) > std::fabs(f.normal[drop])) drop = i;
    }
    for (int k = 0; k < p.corners; ++k) {
        for (int i = 0; i < 3; ++i) {
            f.offset += f.normal[i] * p.rendered[k][i] / p.corners;
            f.extent = std::max(f.extent, std::fabs(static_cast<long double>(p.rendered[k][i])));
        }
    }
    f.u = drop == 0 ? 1 : 0;
    f.v = drop == 2 ? 1 : 2;
    // (u, v, drop) is a right-handed frame or a left-handed one; the normal's sign along drop
    // says which way the boundary turns in it.
    const bool right_handed = (drop == 0) || (drop == 2);  // (1,2,0), (0,1,2); (0,2,1) is not
    f.orientation = ((f.normal[drop] > 0) == right_handed) ? 1 : -1;
    f.ok = true;
    return f;
}

// Where the line of edge p-q crosses the face's interior: the cut's ends as positions s along
// p + s (q - p), each with the boundary edge it lies on; found is false when no part of the
// segment p-q lies inside the face by more than rounding, or p-q is not in its plane.
struct Chord {
    bool found = false;
    long double s[2] = {0, 0};
    int edge[2] = {-1, -1};  // boundary edge k runs from corner k to corner k + 1
};

Chord chord_through(const Piece& face, const FacePlane& f, Vec3 p, Vec3 q) {
    Chord chord;
    long double scale = f.extent;
    for (int i = 0; i < 3; ++i)
        scale = std::max({scale, std::fabs(static_cast<long double>(p[i])),
                          std::fabs(static_cast<long double>(q[i]))});
    const long double tolerance = kCollinearUlps * kRealEpsilon * scale;
    for (const Vec3& end : {p, q}) {
        long double height = -f.offset;
        for (int i = 0; i < 3; ++i) height += f.normal[i] * end[i];
        if (!(std::fabs(height) <= tolerance)) return chord;
    }
    // Each boundary edge's signed distance, inward positive, is linear along the line:
    // at + s * slope. The part deeper than `tolerance` inside every edge, within the segment,
    // must be non-empty; the cut is where the line is inside every edge at all.
    long double deep_lo = 0, deep_hi = 1;
    long double lo = -INFINITY, hi = INFINITY;
    int lo_edge = -1, hi_edge = -1;
    for (int k = 0; k < face.corners; ++k) {
        const Vec3 a = face.rendered[k], b = face.rendered[(k + 1) % face.corners];
        const long double eu = static_cast<long double>(b[f.u]) - a[f.u];
        const long double ev = static_cast<long double>(b[f.v]) - a[f.v];
        const long double length = std::sqrt(eu * eu + ev * ev);
        if (!(length > 0)) return chord;
        const auto distance = [&](Vec3 x) {
            return f.orientation *
                   (eu * (static_cast<long double>(x[f.v]) - a[f.v]) -
                    ev * (static_cast<long double>(x[f.u]) - a[f.u])) /
                   length;
        };
        const long double at = distance(p), slope = distance(q) - at;
        if (slope == 0) {
            if (!(at > tolerance)) return chord;  // along or outside this edge: no cut
            continue;
        }
        // at + s slope >= level  <=>  s >= (level - at) / slope (slope > 0), or <=.
        const long double deep = (tolerance - at) / slope, edge_s = -at / slope;
        if (slope > 0) {
            deep_lo = std::max(deep_lo, deep);
            if (edge_s > lo) lo = edge_s, lo_edge = k;
        } else {
            deep_hi = std::min(deep_hi, deep);
            if (edge_s < hi) hi = edge_s, hi_edge = k;
        }
    }
    if (!(deep_lo < deep_hi) || lo_edge < 0 || hi_edge < 0 || lo_edge == hi_edge) return chord;
    chord.found = true;
    chord.s[0] = lo, chord.s[1] = hi;
    chord.edge[0] = lo_edge, chord.edge[1] = hi_edge;
    return chord;
}

// The face's parts on either side of the chord, each in the face's winding: a point of the
// cut is the edge's own end where it lies within 32 ulps of one, else the face's corner where
// it lies within 32 ulps of one, else a new point on the line written in double. (Within 8,
// the double build kept a second point 2 ulps from a ceiling's corner, and the slivers of
// triangles beside it let paths out of a mirror cell.)
std::vector<Piece> cut_along(const Piece& face, const Chord& chord, const Point& p, const Point& q,
                             const WrittenPoint& centre) {
    Point ends[2];
    int corner_at[2] = {-1, -1};
    for (int e = 0; e < 2; ++e) {
        const long double s = chord.s[e];
        WrittenPoint w;
        for (int axis = 0; axis < 3; ++axis) {
            const double a = coordinate(p.written, axis), b = coordinate(q.written, axis);
            set_coordinate(w, axis, static_cast<double>(a + s * (static_cast<long double>(b) - a)));
        }
        ends[e] = {moved_to_centre(w, centre), w, false};
        // Within rounding of a corner of the edge or of the face: that point itself.
        long double extent = 0;
        for (int axis = 0; axis < 3; ++axis)
            extent = std::max(extent, std::fabs(static_cast<long double>(ends[e].rendered[axis])));
        const long double tolerance = 4 * kCollinearUlps * kRealEpsilon * extent;
        const auto near = [&](Vec3 x) {
            for (int axis = 0; axis < 3; ++axis) {
                if (!(std::fabs(static_cast<long double>(x[axis]) - ends[e].rendered[axis]) <=
                      tolerance))
                    return false;
            }
            return true;
        };
        if (near(p.rendered)) ends[e] = p;
        else if (near(q.rendered)) ends[e] = q;
        for (int k = 0; k < face.corners; ++k) {
            if (near(face.rendered[k])) {
                ends[e] = {face.rendered[k], face.written[k], false};
                corner_at[e] = k;
            }
        }
    }
    if (same(ends[0].rendered, ends[1].rendered)) return {};
    // The boundary with the cut's ends inserted on their edges (or standing for a corner).
    std::vector<Point> boundary;
    int at[2] = {-1, -1};
    for (int k = 0; k < face.corners; ++k) {
        boundary.push_back({face.rendered[k], face.written[k], false});
        for (int e = 0; e < 2; ++e) {
            if (corner_at[e] == k) at[e] = static_cast<int>(boundary.size()) - 1;
        }
        for (int e = 0; e < 2; ++e) {
            if (corner_at[e] < 0 && chord.edge[e] == k) {
                boundary.push_back(ends[e]);
                at[e] = static_cast<int>(boundary.size()) - 1;
            }
        }
    }
    if (at[0] < 0 || at[1] < 0) return {};
    const int m = static_cast<int>(boundary.size());
    std::vector<Piece> parts;
    for (int side = 0; side < 2; ++side) {
        std::vector<Point> polygon;  // from one end of the cut round to the other
        for (int k = at[side];; k = (k + 1) % m) {
            polygon.push_back(boundary[k]);
            if (k == at[1 - side]) break;
        }
        if (polygon.size() < 3) return {};  // the cut runs along the boundary: no cut
        Piece part = face;
        part.corners = static_cast<int>(polygon.size());
        if (polygon.size() == 4) {
            for (int k = 0; k < 4; ++k) part.written[k] = polygon[k].written;
            for (int k = 0; k < 4; ++k) part.rendered[k] = polygon[k].rendered;
            // A rectangle stays one where both parts are rectangles as written: the cut
            // across it at one coordinate.
            bool rect = face.kind == Kind::kRect;
            for (int d : {rect_axis_u(face.axis), rect_axis_v(face.axis)}) {
                if (!rect) break;
                std::vector<double> values;
                for (int k = 0; k < 4; ++k) values.push_back(coordinate(part.written[k], d));
                std::sort(values.begin(), values.end());
                rect = values[0] == values[1] && values[2] == values[3];
            }
            for (int k = 0; rect && k < 4; ++k)
                rect = coordinate(part.written[k], face.axis) ==
                       coordinate(face.written[0], face.axis);
            Vec3 corners[4] = {part.rendered[0], part.rendered[1], part.rendered[2],
                               part.rendered[3]};
            if (rect) {
                part.kind = Kind::kRect;
                parts.push_back(part);
                continue;
            }
            if (is_planar_convex_quad(corners)) {
                part.kind = Kind::kQuad;
                parts.push_back(part);
                continue;
            }
        }
        // A rectangle cut aslant is left whole: its parts would be quads, and so, through
        // demote_rects, would every rectangle of its room (a floor under a triangle standing
        // on it, as in the showcase scene).
        if (face.kind == Kind::kRect) return {};
        // Otherwise triangles, fanned from the polygon's first point (a cut's end).
        for (size_t k = 1; k + 1 < polygon.size(); ++k) {
            Piece t = face;
            t.kind = Kind::kTriangle;
            t.corners = 3;
            const Point* corner[3] = {&polygon[0], &polygon[k], &polygon[k + 1]};
            for (int c = 0; c < 3; ++c) {
                t.written[c] = corner[c]->written;
                t.rendered[c] = corner[c]->rendered;
            }
            parts.push_back(t);
        }
    }
    return parts;
}

// The pieces in a uniform grid over their bounds (at most 32 cells a side), each in every
// cell its box covers: an edge looks only at the faces whose boxes meet its own.
class FaceIndex {
public:
    explicit FaceIndex(const std::vector<Piece>& pieces) : stamp_(pieces.size(), 0) {
        if (pieces.empty()) return;
        for (int axis = 0; axis < 3; ++axis) {
            lo_[axis] = hi_[axis] = pieces[0].rendered[0][axis];
            for (const Piece& p : pieces) {
                for (int k = 0; k < p.corners; ++k) {
                    lo_[axis] = std::min(lo_[axis], double(p.rendered[k][axis]));
                    hi_[axis] = std::max(hi_[axis], double(p.rendered[k][axis]));
                }
            }
        }
        side_ = std::max(1, std::min(32, static_cast<int>(std::cbrt(double(pieces.size())))));
        cells_.resize(size_t(side_) * side_ * side_);
        for (size_t i = 0; i < pieces.size(); ++i) {
            Vec3 a = pieces[i].rendered[0], b = a;
            for (int k = 1; k < pieces[i].corners; ++k) {
                a = lower(a, pieces[i].rendered[k]);
                b = upper(b, pieces[i].rendered[k]);
            }
            visit_cells(a, b, [&](size_t c) { cells_[c].push_back(i); });
        }
    }

    // Calls visit(i) once for each piece whose box may meet the box with corners a and b.
    template <typename Visit>
    void near_box(Vec3 a, Vec3 b, Visit visit) {
        ++round_;
        visit_cells(lower(a, b), upper(a, b), [&](size_t c) {
            for (size_t i : cells_[c]) {
                if (stamp_[i] == round_) continue;
                stamp_[i] = round_;
                visit(i);
            }
        });
    }

private:
    template <typename Visit>
    void visit_cells(Vec3 a, Vec3 b, Visit visit) const {
        int from[3], to[3];
        for (int axis = 0; axis < 3; ++axis) {
            const double margin = 4 * kCollinearUlps * kRealEpsilon *
                                  std::max(std::fabs(lo_[axis]), std::fabs(hi_[axis]));
            from[axis] = cell(axis, a[axis] - margin);
            to[axis] = cell(axis, b[axis] + margin);
        }
        for (int i = from[0]; i <= to[0]; ++i)
            for (int j = from[1]; j <= to[1]; ++j)
                for (int k = from[2]; k <= to[2]; ++k) visit((size_t(i) * side_ + j) * side_ + k);
    }
    int cell(int axis, double x) const {
        const double extent = hi_[axis] - lo_[axis];
        if (!(extent > 0)) return 0;
        const double at = (x - lo_[axis]) / extent * side_;
        return at <= 0 ? 0 : (at >= side_ - 1 ? side_ - 1 : static_cast<int>(at));
    }

    double lo_[3] = {0, 0, 0}, hi_[3] = {0, 0, 0};
    int side_ = 1;
    std::vector<std::vector<size_t>> cells_;
    std::vector<unsigned> stamp_;
    unsigned round_ = 0;
};

// One pass of cuts: every face that an edge of another piece, at an angle to it, crosses inside
// (an edge no two pieces share: a mesh's inner edges run along their neighbours, not across
// them) is cut once along that edge's line. Returns whether any was.
bool cut_at_inner_edges(std::vector<Piece>& pieces, const WrittenPoint& centre) {
    // The edges no two pieces share, as (piece, edge) pairs.
    std::vector<EdgeUse> edges;
    for (size_t i = 0; i < pieces.size(); ++i) {
        if (flat(pieces[i])) continue;
        for (int k = 0; k < pieces[i].corners; ++k)
            edges.push_back({edge_of(pieces[i].rendered, pieces[i].corners, k), i, k});
    }
    std::sort(edges.begin(), edges.end());
    std::vector<std::pair<size_t, int>> borders;
    for (size_t a = 0, b; a < edges.size(); a = b) {
        for (b = a + 1; b < edges.size() && edges[b].key == edges[a].key;) ++b;
        if (b == a + 1) borders.push_back({edges[a].holder, edges[a].edge});
    }
    if (borders.empty()) return false;  // a closed mesh: nothing to look up
    FaceIndex faces(pieces);
    std::vector<FacePlane> planes(pieces.size());
    std::vector<bool> has_plane(pieces.size(), false), is_cut(pieces.size(), false);
    const auto plane = [&](size_t i) -> const FacePlane& {
        if (!has_plane[i]) planes[i] = face_plane(pieces[i]), has_plane[i] = true;
        return planes[i];
    };
    std::vector<std::vector<Piece>> parts(pieces.size());
    bool cut = false;
    for (const auto& border : borders) {
        // Named copies, not a structured binding: a lambda below uses them, and clang before
        // 16 (the race check's compiler) cannot capture a structured binding.
        const auto g = border.first;
        const auto k = border.second;
        const Piece& owner = pieces[g];
        const int next = (k + 1) % owner.corners;
        const Vec3 p = owner.rendered[k], q = owner.rendered[next];
        const Point pw{p, owner.written[k], false}, qw{q, owner.written[next], false};
        faces.near_box(p, q, [&](size_t f) {
            if (f == g || is_cut[f] || flat(pieces[f]) || !plane(f).ok) return;
            // Pieces of one plane that overlap (a bow tie's halves) are left as they are:
            // the faces to close are those that meet at an angle.
            if (plane(g).ok && std::fabs(planes[f].normal[0] * planes[g].normal[0] +
                                         planes[f].normal[1] * planes[g].normal[1] +
                                         planes[f].normal[2] * planes[g].normal[2]) > 1 - 1e-6L)
                return;
            const Chord chord = chord_through(pieces[f], planes[f], p, q);
            if (!chord.found) return;
            std::vector<Piece> split = cut_along(pieces[f], chord, pw, qw, centre);
            if (split.empty()) return;
            parts[f] = std::move(split);
            is_cut[f] = true;
            cut = true;
        });
    }
    if (!cut) return false;
    std::vector<Piece> next;
    for (size_t i = 0; i < pieces.size(); ++i) {
        if (is_cut[i]) next.insert(next.end(), parts[i].begin(), parts[i].end());
        else next.push_back(pieces[i]);
    }
    pieces = std::move(next);
    return true;
}

// One pass: faces cut along edges that cross them (cut_at_inner_edges), every piece split where
// the scene's current vertices lie on its edges, then the rectangles that now meet triangles or
// quads demoted. Returns whether anything changed.
bool split_once(std::vector<Piece>& pieces, const WrittenPoint& centre) {
    bool changed = cut_at_inner_edges(pieces, centre);  // its new points come rendered
    const PointIndex index(pieces);
    std::vector<Piece> next;
    for (const Piece& piece : pieces) {
        std::vector<Piece> parts;
        if (!flat(piece))
            parts = piece.kind == Kind::kRect ? cut(piece, index) : fan(piece, index, centre);
        if (parts.empty()) {
            next.push_back(piece);
            continue;
        }
        for (Piece& part : parts) {
            for (int k = 0; k < part.corners; ++k)
                part.rendered[k] = moved_to_centre(part.written[k], centre);
            next.push_back(part);
        }
        changed = true;
    }
    pieces = std::move(next);
    return demote_rects(pieces) > 0 || changed;
}

// Enough for a chain of rectangles demoted one neighbour per pass; each pass of a scene
// without T-junctions left changes nothing and ends the search.
constexpr int kMaxPasses = 32;

// Marks the cut edges of the scene's triangles and convex quads (cut_edges, triangle.h's
// step_off_cut_edge): an edge that a piece of the same plane shares end to end, where a third
// face meets them (three or more primitives hold it). Returns how many it marked.
int mark_cut_edges(Scene& scene) {
    // Every edge with its holder: triangles, then quads, then rectangles, by index.
    std::vector<Triangle>& triangles = scene.of<Triangle>();
    std::vector<ConvexQuad>& quads = scene.of<ConvexQuad>();
    const std::vector<AxisRect>& rects = scene.of<AxisRect>();
    std::vector<EdgeUse> edges;
    std::vector<Vec3> normals;
    for (const Triangle& t : triangles) {
        const Vec3 v[3] = {t.v0, t.v1, t.v2};
        for (int k = 0; k < 3; ++k) edges.push_back({edge_of(v, 3, k), normals.size(), k});
        normals.push_back(t.normal);
    }
    for (const ConvexQuad& q : quads) {
        const Vec3 v[4] = {q.v0, q.v1, q.v2, q.v3};
        for (int k = 0; k < 4; ++k) edges.push_back({edge_of(v, 4, k), normals.size(), k});
        normals.push_back(q.normal);
    }
    for (const AxisRect& r : rects) {
        Vec3 v[4];
        rect_corners(r, v);
        for (int k = 0; k < 4; ++k) edges.push_back({edge_of(v, 4, k), normals.size(), k});
        normals.push_back(along_axis(rect_axis(r), 1.0f));
    }
    for (Triangle& t : triangles) t.cut_edges = 0;
    for (ConvexQuad& q : quads) q.cut_edges = 0;
    std::sort(edges.begin(), edges.end());
    const auto parallel = [](Vec3 m, Vec3 n) {
        return std::fabs(double(m.x) * n.x + double(m.y) * n.y + double(m.z) * n.z) > 1 - 1e-6;
    };
    int marked = 0;
    for (size_t a = 0, b; a < edges.size(); a = b) {
        for (b = a + 1; b < edges.size() && edges[b].key == edges[a].key;) ++b;
        if (b - a < 3) continue;  // no third face
        for (size_t i = a; i < b; ++i) {
            const size_t h = edges[i].holder;
            if (h >= triangles.size() + quads.size()) continue;  // a rectangle: no mark
            int coplanar = 0;  // this piece among them
            for (size_t j = a; j < b; ++j)
                coplanar += parallel(normals[h], normals[edges[j].holder]);
            if (coplanar < 2) continue;
            int& bits = h < triangles.size() ? triangles[h].cut_edges
                                             : quads[h - triangles.size()].cut_edges;
            if (bits == 0) ++marked;
            bits |= 1 << edges[i].edge;
        }
    }
    return marked;
}

}  // namespace

int split_t_junctions(Scene& scene) {
    const WrittenCoordinates& w = scene.written;
    if (!w.present || w.triangle_vertices.size() != 3 * scene.of<Triangle>().size() ||
        w.quad_vertices.size() != 4 * scene.of<ConvexQuad>().size() ||
        w.rect_vertices.size() != 4 * scene.of<AxisRect>().size())
        return 0;  // a scene built in code: no written points to split on
    const WrittenPoint centre = centring_centre(scene);
    std::vector<Piece> pieces;
    const auto add = [&](Kind kind, int corners, const WrittenPoint* written, int material,
                         int axis) {
        Piece p;
        p.kind = kind;
        p.corners = corners;
        p.material = material;
        p.axis = axis;
        for (int k = 0; k < corners; ++k) {
            p.written[k] = written[k];
            p.rendered[k] = moved_to_centre(written[k], centre);
        }
        pieces.push_back(p);
    };
    for (size_t i = 0; i < scene.of<Triangle>().size(); ++i)
        add(Kind::kTriangle, 3, &w.triangle_vertices[3 * i], scene.of<Triangle>()[i].material, -1);
    for (size_t i = 0; i < scene.of<ConvexQuad>().size(); ++i)
        add(Kind::kQuad, 4, &w.quad_vertices[4 * i], scene.of<ConvexQuad>()[i].material, -1);
    for (size_t i = 0; i < scene.of<AxisRect>().size(); ++i)
        add(Kind::kRect, 4, &w.rect_vertices[4 * i], scene.of<AxisRect>()[i].material,
            rect_axis(scene.of<AxisRect>()[i]));
    const size_t before = pieces.size();

    bool changed = false;
    for (int pass = 0; pass < kMaxPasses && split_once(pieces, centre); ++pass) changed = true;
    if (!changed) {
        mark_cut_edges(scene);  // a file may hold such joints already cut
        return 0;  // every other bit as loaded
    }

    // Rebuilt from the written points, rounded once, as the loader builds the file's own.
    scene.of<Triangle>().clear();
    scene.of<ConvexQuad>().clear();
    scene.of<AxisRect>().clear();
    WrittenCoordinates& out = scene.written;
    out.triangle_vertices.clear();
    out.quad_vertices.clear();
    out.rect_vertices.clear();
    for (const Piece& p : pieces) {
        Vec3 v[4];
        for (int k = 0; k < p.corners; ++k) v[k] = rounded(p.written[k]);
        if (p.kind == Kind::kTriangle) {
            scene.of<Triangle>().push_back(make_triangle(v[0], v[1], v[2], p.material));
            out.triangle_vertices.insert(out.triangle_vertices.end(), p.written, p.written + 3);
        } else if (p.kind == Kind::kQuad) {
            scene.of<ConvexQuad>().push_back(make_convex_quad(v[0], v[1], v[2], v[3], p.material));
            out.quad_vertices.insert(out.quad_vertices.end(), p.written, p.written + 4);
        } else {
            scene.of<AxisRect>().push_back(make_axis_rect(v, p.axis, p.material));
            out.rect_vertices.insert(out.rect_vertices.end(), p.written, p.written + 4);
        }
    }
    mark_cut_edges(scene);
    return static_cast<int>(pieces.size() - before);
}
