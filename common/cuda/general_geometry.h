// The same scene in more general primitives: its axis-aligned rectangles as the convex quads
// they also are, or every quad as two triangles. Lab 05 measures what each kind of primitive
// test costs on one scene this way (lab05-bench's geometry shapes), and renders the general
// path on demand (RT_LAB05_GEOMETRY=general) so that the tests can check it draws the same
// image. Host only; the surfaces are the same, so the estimator is too. As quads, rectangles
// keep their distances and normals to the bit, so with one seed the image is the same but
// for rays through an edge to the last bit (tests/unit/test_general_geometry.cpp); as
// triangles the distances differ by rounding and the images agree statistically.
#pragma once

#include <cstring>
#include <string>
#include <vector>

#include <errors.h>
#include <scene_view.h>

enum class GeometryForm {
    AsLoaded,   // the scene's own primitives
    Quads,      // rectangles as convex quads: what a scene whose walls are not axis-aligned has
    Triangles,  // rectangles and quads as two triangles each (v0 v1 v2 and v0 v2 v3)
};

// A scene view whose primitive arrays may be replaced by re-expressed ones, which it owns.
// Not copyable: `view` points into its own vectors.
class SceneInForm {
public:
    SceneInForm(const SceneView& scene, GeometryForm form) : view(scene) {
        if (form == GeometryForm::AsLoaded) return;
        quads_.assign(scene.of<ConvexQuad>().items,
                      scene.of<ConvexQuad>().items + scene.of<ConvexQuad>().count);
        for (int i = 0; i < scene.of<AxisRect>().count; ++i) {
            Vec3 v[4];
            rect_corners(scene.of<AxisRect>()[i], v);
            quads_.push_back(
                make_convex_quad(v[0], v[1], v[2], v[3], scene.of<AxisRect>()[i].material));
            // The rectangle's own normal. make_convex_quad's equals it but for the signs of its
            // zeros (the cross product can give -0), and the sign of a zero component picks
            // the tangent frame of cosine sampling (sample_cosine_hemisphere): with a -0 every
            // bounce off that wall would draw other directions from the same random numbers.
            quads_.back().normal = rect_normal(scene.of<AxisRect>()[i]);
        }
        view.of<AxisRect>().items = nullptr;
        view.of<AxisRect>().count = 0;
        if (form == GeometryForm::Triangles) {
            triangles_.assign(scene.of<Triangle>().items,
                              scene.of<Triangle>().items + scene.of<Triangle>().count);
            for (size_t k = 0; k < quads_.size(); ++k) {
                const ConvexQuad& q = quads_[k];
                triangles_.push_back(make_triangle(q.v0, q.v1, q.v2, q.material));
                triangles_.push_back(make_triangle(q.v0, q.v2, q.v3, q.material));
                // A rectangle's two triangles: its normal too, as above.
                if (k >= static_cast<size_t>(scene.of<ConvexQuad>().count))
                    triangles_.end()[-2].normal = triangles_.end()[-1].normal = q.normal;
            }
            quads_.clear();
            view.of<Triangle>().items = triangles_.data();
            view.of<Triangle>().count = static_cast<int>(triangles_.size());
        }
        view.of<ConvexQuad>().items = quads_.empty() ? nullptr : quads_.data();
        view.of<ConvexQuad>().count = static_cast<int>(quads_.size());
    }
    SceneInForm(const SceneInForm&) = delete;
    SceneInForm& operator=(const SceneInForm&) = delete;

    SceneView view;

private:
    std::vector<ConvexQuad> quads_;
    std::vector<Triangle> triangles_;
};

// Lab 05's renderer reads RT_LAB05_GEOMETRY: unset or "scene" renders the scene's own
// primitives, "general" its rectangles as convex quads with the kernel for general geometry.
// Anything else is bad input: one line, exit status 2.
inline GeometryForm lab05_geometry_form(const char* setting) {
    if (setting == nullptr || std::strcmp(setting, "") == 0 || std::strcmp(setting, "scene") == 0)
        return GeometryForm::AsLoaded;
    if (std::strcmp(setting, "general") == 0) return GeometryForm::Quads;
    throw InputError(std::string("RT_LAB05_GEOMETRY: expected 'scene' or 'general', got '") +
                     setting + "'");
}
