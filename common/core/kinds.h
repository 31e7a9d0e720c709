// A set of kinds is a list of types: Kinds<Sphere, AxisRect> is the set of spheres and
// axis-aligned rectangles, Kinds<Diffuse> the diffuse material alone. Each family declares its
// full list once (AllPrimitives in geometry_set.h, AllMaterials in material.h); a kind's number
// (in a Hit, a packed hit, a material table) is its position there, and every set a renderer is
// compiled for names its kinds. A new kind joins its family's list and every set built from
// that list follows.
//
// Header-only and free of the C++ library, so nvcc compiles it for the device (core/'s rule).
#pragma once

#include <rt_hd.h>

template <class... K>
struct Kinds {
    static constexpr int kCount = sizeof...(K);
};

// A kind carried as a value, so a generic lambda can be called once per kind.
template <class K>
struct KindTag {
    using type = K;
};

namespace kinds_detail {

template <class A, class B>
struct Same {
    static constexpr bool value = false;
};
template <class A>
struct Same<A, A> {
    static constexpr bool value = true;
};

template <class Set, class K>
struct Position;
template <class K>
struct Position<Kinds<>, K> {
    static constexpr int value = -1;
};
template <class K, class First, class... Rest>
struct Position<Kinds<First, Rest...>, K> {
    static constexpr int rest = Position<Kinds<Rest...>, K>::value;
    static constexpr int value = Same<First, K>::value ? 0 : (rest < 0 ? -1 : rest + 1);
};

template <bool kFirst, class A, class B>
struct Conditional {
    using type = A;
};
template <class A, class B>
struct Conditional<false, A, B> {
    using type = B;
};

template <class Set, class K, class Kept = Kinds<>>
struct Without;
template <class K, class... Kept>
struct Without<Kinds<>, K, Kinds<Kept...>> {
    using type = Kinds<Kept...>;
};
template <class First, class... Rest, class K, class... Kept>
struct Without<Kinds<First, Rest...>, K, Kinds<Kept...>> {
    using type = typename Without<Kinds<Rest...>, K,
                                  typename Conditional<Same<First, K>::value, Kinds<Kept...>,
                                                       Kinds<Kept..., First>>::type>::type;
};

template <class Sub, class Set>
struct Within;
template <class... K, class Set>
struct Within<Kinds<K...>, Set> {
    static constexpr bool value = (true && ... && (Position<Set, K>::value >= 0));
};

}  // namespace kinds_detail

// Set without the kind K, in Set's order.
template <class Set, class K>
using without_kind = typename kinds_detail::Without<Set, K>::type;

// K's position in Set, -1 when Set does not hold it.
template <class Set, class K>
constexpr int kind_index = kinds_detail::Position<Set, K>::value;

// Whether Set holds K.
template <class Set, class K>
constexpr bool has_kind = kind_index<Set, K> >= 0;

// Whether every kind of Sub is in Set.
template <class Sub, class Set>
constexpr bool kinds_within = kinds_detail::Within<Sub, Set>::value;

// Calls f(KindTag<K>{}) for every kind of the set, in the list's order. Host and device: f
// is whatever the caller is (a host-only loop hands it a host lambda, which nvcc would
// otherwise refuse to see called from here).
#ifdef __CUDACC__
#pragma nv_exec_check_disable
#endif
template <class... K, class F>
RT_HD inline void for_each_kind(Kinds<K...>, F&& f) {
    (f(KindTag<K>{}), ...);
}

// One Slot<K> per kind K of a list, reached by kind: PerKind<KindSpan, AllPrimitives> holds a
// KindSpan<Sphere>, a KindSpan<Triangle>, ... and of<Sphere>() is the first. What a scene
// keeps per kind (its arrays, their places in a GPU pool, their counts) is declared this way,
// so a kind added to the list gets its slot everywhere.
template <template <class> class Slot, class List>
struct PerKind;
template <template <class> class Slot, class... K>
struct PerKind<Slot, Kinds<K...>> : Slot<K>... {
    template <class T>
    RT_HD Slot<T>& of() {
        return *this;
    }
    template <class T>
    RT_HD const Slot<T>& of() const {
        return *this;
    }
};

// The bits a field needs to number `count` kinds (0..count-1).
constexpr int bits_to_number(int count) {
    int bits = 0;
    while ((1 << bits) < count) ++bits;
    return bits;
}
