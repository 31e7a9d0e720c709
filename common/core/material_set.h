// Which kinds of material a renderer is compiled for. The bounce step branches on the
// material of every hit; a scene that has only diffuse surfaces (the Cornell baseline) never
// takes the mirror or glass branch, but a renderer compiled for every material still carries
// that code: on a GPU its registers count against every thread (the glass branch's Fresnel
// and refraction push the megakernel past its register budget into spills). A renderer
// instantiated for the scene's own set carries only what the scene uses.
//
// A set names its kinds (Kinds<Diffuse>, kinds.h), drawn from AllMaterials (material.h); each
// is a type, so the choice is made once per render by dispatch (has_specular_material) and the
// compiler removes the unused branches (`if constexpr` in bounce_step).
#pragma once

#include <kinds.h>
#include <material.h>
#include <rt_hd.h>

using AnyMaterial = AllMaterials;  // every scene: the default
using DiffuseOnly = Kinds<Diffuse>;  // scenes without mirrors or glass

// Whether a set holds any kind but the diffuse one: the bounce step's specular branch.
template <class Set>
constexpr bool has_specular = Set::kCount > (has_kind<Set, Diffuse> ? 1 : 0);

// What a scene's material table holds: whether a renderer for DiffuseOnly may render it.
// (A table entry that no primitive uses counts too: the check stays one loop over a short
// table, and a set too large costs speed, never correctness.)
RT_HD inline bool has_specular_material(const Material* materials, int count) {
    for (int i = 0; i < count; ++i) {
        if (materials[i].type != material_type<Diffuse>) return true;
    }
    return false;
}
