#include "shading/map_shading.hpp"
#include "shading/scene_cache.hpp"
#include "shading/shadow_edges.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <functional>
#include <utility>

#include "scene/camera.hpp"
#include "raster/cube_map.hpp"
#include "base/enum_names.hpp"
#include "base/error.hpp"
#include "io/image_io.hpp"
#include "base/parallel.hpp"
#include "raster/raster.hpp"
#include "reference/raytrace.hpp"
#include "shading/resolve.hpp"
#include "material/shading.hpp"

namespace abcube {

namespace {

constexpr EnumName<EnvmapLookup> LOOKUP_NAMES[] = {
    {EnvmapLookup::reflected, "R"}, {EnvmapLookup::bisector, "bisector"}, {EnvmapLookup::position, "position"}};

}  // namespace

const char* envmap_lookup_name(EnvmapLookup l) { return enum_name(LOOKUP_NAMES, l); }

bool parse_envmap_lookup(const std::string& s, EnvmapLookup* out) { return parse_enum(LOOKUP_NAMES, s, out); }

void RayErrors::merge(const RayErrors& o) {
  error_cp.merge(o.error_cp);
  error_parallax.merge(o.error_parallax);
  false_hits += o.false_hits;
  wrong_object += o.wrong_object;
}

void MapShadingStats::merge(const MapShadingStats& o) {
  searches.merge(o.searches);
  lens_transfers += o.lens_transfers;
  lens_fallbacks += o.lens_fallbacks;
  envmap_lookups += o.envmap_lookups;
  multi_point_fragments += o.multi_point_fragments;
  shadow_edge_fragments += o.shadow_edge_fragments;
  shadow_edge_samples += o.shadow_edge_samples;
  shadow_edge_pixels += o.shadow_edge_pixels;
  secondary_edge_fragments += o.secondary_edge_fragments;
  secondary_edge_samples += o.secondary_edge_samples;
  secondary_edge_pixels += o.secondary_edge_pixels;
  sparse_pixels += o.sparse_pixels;
  errors.merge(o.errors);
}

SurfacePoint surface_point(const SceneData& scene, uint32_t triangle, const glm::dvec3& point) {
  const TriangleSoup& t = *scene.triangles;
  const size_t base = 3 * static_cast<size_t>(triangle);
  const glm::dvec3 a(t.positions[base]), b(t.positions[base + 1]), c(t.positions[base + 2]);
  SurfacePoint sp;
  sp.point = point;
  sp.triangle = triangle;
  sp.object = t.object_id[triangle];
  sp.material = t.material_id[triangle];
  const glm::dvec3 ng = glm::cross(b - a, c - a);
  const double area2 = glm::dot(ng, ng);
  sp.geometric_normal = area2 > 0.0 ? ng / std::sqrt(area2) : glm::dvec3(0, 0, 1);
  const glm::dvec3 w = barycentric_weights(t, triangle, point);
  const glm::dvec3 n =
      w.x * glm::dvec3(t.normals[base]) + w.y * glm::dvec3(t.normals[base + 1]) + w.z * glm::dvec3(t.normals[base + 2]);
  const double len = glm::length(n);
  sp.shading_normal = len > 0.0 && std::isfinite(len) ? n / len : sp.geometric_normal;
  return sp;
}

MapShader::MapShader(const SceneData& scene, const CubeABuffer& cube, const MapShadingOptions& options,
                     const RayTracer* reference, const SceneCache* cache)
    : scene_(scene), cube_(cube), options_(options), reference_(reference) {
  ctx_ = std::make_shared<SearchContext>(scene, cube, [cache]() -> std::shared_ptr<const MeshNeighbours> {
    return cache ? cache->neighbours() : nullptr;  // asked for once the side structure is built
  });
  lens_of_object_.assign(scene.objects.size(), -1);
  if (options_.refraction != RefractionMode::search) {
    lenses_ = cache ? *cache->lenses() : fit_lenses(scene);
    for (size_t i = 0; i < lenses_.size(); ++i) {
      if (lenses_[i].valid) lens_of_object_[lenses_[i].object] = static_cast<int>(i);
    }
  }
  set_method_state();
}

MapShader::MapShader(const MapShader& base, const MapShadingOptions& options, const RayTracer* reference)
    : scene_(base.scene_),
      cube_(base.cube_),
      options_(options),
      reference_(reference),
      ctx_(base.ctx_),
      lenses_(base.lenses_),
      lens_of_object_(base.lens_of_object_) {
  ABCUBE_CHECK(options.variant == base.options_.variant && options.refraction == base.options_.refraction,
               "a shader over another's map keeps its variant and refraction");
  set_method_state();
}

void MapShader::set_method_state() {
  options_.search.layers = options_.variant == MapVariant::zbuffer ? SearchLayers::nearest : SearchLayers::all;
  if (options_.variant == MapVariant::envmap) {
    env_colour_ = CubeImage(cube_.n, 3);
    texel_state_ =
        std::make_unique<std::atomic<uint8_t>[]>(6 * static_cast<size_t>(cube_.n) * static_cast<size_t>(cube_.n));
  }
}

MapShader::~MapShader() = default;

glm::dvec3 MapShader::shade(const SurfacePoint& sp, const glm::dvec3& dir, int depth, bool primary,
                            MapShadingStats* stats, PrimaryLights* direct, KnownBlockers* known) const {
  const MediumCrossing c{sp.triangle, !(glm::dot(sp.geometric_normal, dir) < 0.0), 0.0};
  if (direct) direct->trail = 0;
  return shade(Crossed{sp, sp.point, ctx_->media().resolve(MediumStack{}, &c, 1)}, dir, depth, primary, stats, known,
               direct, direct ? &direct->trail : nullptr);
}

glm::dvec3 MapShader::secondary(const SurfacePoint& sp, const glm::dvec3& dir, MapShadingStats* stats, uint64_t* trail,
                                KnownBlockers* known) const {
  const MediumCrossing c{sp.triangle, !(glm::dot(sp.geometric_normal, dir) < 0.0), 0.0};
  if (trail) *trail = 0;
  const Terms t = secondary_terms(Crossed{sp, sp.point, ctx_->media().resolve(MediumStack{}, &c, 1)}, dir, 0, true,
                                  stats, known, trail);
  return t.reflected + t.transmitted;
}

// kr times the reflected ray's colour, kt times the transmitted one's (THE RULES).
MapShader::Terms MapShader::secondary_terms(const Crossed& cr, const glm::dvec3& dir, int depth, bool primary,
                                            MapShadingStats* stats, KnownBlockers* known, uint64_t* trail) const {
  const SurfacePoint& sp = cr.sp;
  const SecondaryWeights w =
      secondary_weights(scene_.materials[sp.material], scene_.render.fresnel, dir,
                        transmission_between(dir, sp.geometric_normal, sp.shading_normal, cr.itf.n_from, cr.itf.n_to),
                        sp.geometric_normal);
  Terms t;
  if (depth < scene_.render.max_depth && w.reflect > 0.0) {
    t.reflected = w.reflect * reflected(sp, dir, depth, primary, cr.itf.before, stats, known, trail);
  }
  if (depth < scene_.render.max_depth && w.transmit > 0.0) {
    t.transmitted = w.transmit * transmitted(cr, dir, depth, stats, known, trail);
  }
  return t;
}

glm::dvec3 MapShader::shade(const Crossed& cr, const glm::dvec3& dir, int depth, bool primary, MapShadingStats* stats,
                            KnownBlockers* known, PrimaryLights* direct, uint64_t* trail) const {
  const SurfacePoint& sp = cr.sp;
  const Material& m = scene_.materials[sp.material];
  // Coverage transparency of a found surface: the ray goes on behind it, same depth.
  glm::dvec3 behind(0.0);
  const bool blend = !primary && m.opacity < 1.0;
  if (blend) {
    behind = trace(cr.far, dir, depth, cr.itf.after, stats, known, nullptr, trail);
    if (m.opacity <= 0.0) return behind;
  }
  const glm::dvec3 v = -dir;
  const glm::dvec3 n = face_forward(sp.shading_normal, v);
  const glm::dvec3 od = sp.diffuse_given ? sp.diffuse : diffuse_color_at(scene_, sp.triangle, sp.point);
  glm::dvec3 c =
      phong_ambient(m, scene_.ambient, od) + lights(sp, v, n, od, stats, known, depth == 0 ? direct : nullptr);
  const Terms t = secondary_terms(cr, dir, depth, primary, stats, known, trail);
  if (depth == 0 && direct) direct->secondary = t.reflected + t.transmitted;
  c += t.reflected;  // in this order, term by term: the same sums as ever
  c += t.transmitted;
  return blend ? blend_coverage(m.opacity, c, behind) : c;
}

// sum_l S_l phong_light, S_l from the shadow search (thesis 8.3).
glm::dvec3 MapShader::visibility(const glm::dvec3& p, size_t light, MapShadingStats* stats,
                                 KnownBlockers* known) const {
  const ShadowResult s = shadow(p, scene_.lights[light].position, known ? known->of(light) : NO_TRIANGLE);
  if (known) known->note(light, s.opaque_blocker);
  if (stats) stats->searches.shadow.add(s);
  return s.transmittance;
}

glm::dvec3 MapShader::lights(const SurfacePoint& sp, const glm::dvec3& v, const glm::dvec3& n, const glm::dvec3& od,
                             MapShadingStats* stats, KnownBlockers* known, PrimaryLights* direct) const {
  const Material& m = scene_.materials[sp.material];
  if (direct) {
    direct->lit.assign(scene_.lights.size(), glm::dvec3(0.0));
    direct->shadow.assign(scene_.lights.size(), glm::dvec3(1.0));
  }
  glm::dvec3 c(0.0);
  for (size_t l = 0; l < scene_.lights.size(); ++l) {
    const PointLight& light = scene_.lights[l];
    const glm::dvec3 to_light = light.position - sp.point;
    if (to_light == glm::dvec3(0.0)) continue;
    const glm::dvec3 lit = phong_light(m, n, v, glm::normalize(to_light), light.color, od);
    if (lit == glm::dvec3(0.0)) continue;
    if (direct) direct->lit[l] = lit;
    if (!light.cast_shadows) {
      if (options_.walk_all_shadows) {
        const ShadowResult unused = shadow(sp.point, light.position, NO_TRIANGLE);
        if (stats) stats->searches.shadow.add(unused);
      }
      c += lit;
      continue;
    }
    const glm::dvec3 shadow = visibility(sp.point, l, stats, known);
    if (direct) direct->shadow[l] = shadow;
    c += lit * shadow;
  }
  return c;
}

// The search for a ray from w along dir: from inside the top medium, or in air.
SearchResult MapShader::search(const glm::dvec3& w, const glm::dvec3& dir, const MediumStack& stack,
                               MapShadingStats* stats, bool defer) const {
  const bool inside = !stack.empty();
  const SearchRay q = inside ? refraction_exit_ray(*ctx_, w, dir, ctx_->media().top(stack), options_.search)
                             : reflection_ray(*ctx_, w, dir, options_.search);
  const SearchResult r = deferred_ && defer ? deferred_->search(q) : search_along(*ctx_, q, options_.search);
  if (stats) (inside ? stats->searches.refraction_exit : stats->searches.reflection).add(r);
  return r;
}

ShadowResult MapShader::shadow(const glm::dvec3& p, const glm::dvec3& light_position, uint32_t known_blocker) const {
  if (!deferred_) return shadow_search(*ctx_, p, light_position, options_.search, known_blocker);
  ShadowResult res;
  SearchRay q;
  if (!shadow_ray(*ctx_, p, light_position, options_.search, &q)) return res;
  if (known_blocker_answer(*ctx_, q, light_position, options_.search, known_blocker, &res)) return res;
  return deferred_->shadow(q, light_position);
}

// The crossing set of a found surface (media.hpp): with the surfaces crossed together with
// it when it is a medium's.
MapShader::Crossed MapShader::crossing_set(const glm::dvec3& w, const glm::dvec3& dir, const SearchResult& r,
                                           const MediumStack& stack) const {
  const Media& media = ctx_->media();
  Crossed c{surface_point(scene_, r.triangle, r.point), r.point, {}};
  const auto leaving = [&](uint32_t tri) { return !(glm::dot(ctx_->plane(tri).normal, dir) < 0.0); };
  std::vector<MediumCrossing> set{{r.triangle, leaving(r.triangle), r.distance}};
  if (media.is_medium(r.triangle)) {
    coincident_crossings(*ctx_, w, dir, r.triangle, r.distance, media.tolerance(r.point), [&](uint32_t tri, double l) {
      set.push_back({tri, leaving(tri), l});
    });
  }
  c.itf = media.resolve(stack, set.data(), set.size());
  if (set.size() == 1) return c;
  double far_l = r.distance;
  for (const MediumCrossing& k : set) {
    if (k.t > far_l) far_l = k.t;
    if (k.triangle == c.itf.triangle && k.triangle != r.triangle)
      c.sp = surface_point(scene_, k.triangle, w + k.t * dir);
  }
  c.far = far_l > r.distance ? w + far_l * dir : r.point;
  return c;
}

// What a ray from w along dir finds in the map, shaded one bounce deeper (or background).
glm::dvec3 MapShader::trace(const glm::dvec3& w, const glm::dvec3& dir, int depth, const MediumStack& stack,
                            MapShadingStats* stats, KnownBlockers* known, SearchResult* found, uint64_t* trail) const {
  const SearchResult r = search(w, dir, stack, stats);
  if (found) *found = r;
  if (trail) {  // an order-dependent mix of the object found (0: none)
    const uint64_t id = r.hit ? uint64_t{scene_.triangles->object_id[r.triangle]} + 1 : 0;
    *trail = (*trail ^ id) * 0x9e3779b97f4a7c15ull + 0x632be59bd9b4e019ull;
  }
  if (!r.hit) return scene_.background;
  const Crossed c = crossing_set(w, dir, r, stack);
  if (c.itf.pass) {  // no interface: the same ray goes on from the crossing
    if (c.itf.after.passes > MEDIA_MAX_PASSES) return scene_.background;
    return trace(c.far, dir, depth, c.itf.after, stats, known, nullptr, trail);
  }
  return shade(c, dir, depth, false, stats, known, nullptr, trail);
}

glm::dvec3 MapShader::reflected(const SurfacePoint& sp, const glm::dvec3& dir, int depth, bool primary,
                                const MediumStack& stack, MapShadingStats* stats, KnownBlockers* known,
                                uint64_t* trail) const {
  const glm::dvec3 r = glm::normalize(reflect_dir(dir, sp.shading_normal));
  if (options_.variant == MapVariant::envmap) {
    if (stats) ++stats->envmap_lookups;
    const glm::dvec3 lookup = envmap_direction(sp.point, r);
    if (primary && reference_ && stats) measure(sp, r, nullptr, &lookup, stats);
    return envmap_at(lookup);
  }
  SearchResult found;
  const glm::dvec3 c = trace(sp.point, r, depth + 1, stack, stats, known, &found, trail);
  if (primary && reference_ && stats) measure(sp, r, &found, nullptr, stats);
  return c;
}

// The transmitted ray of an interface and the stack it carries: from the furthest crossing
// in the media after it, or, on total internal reflection, from the surface in those before.
Ray MapShader::transmitted_ray(const Crossed& c, const Transmission& tr, MediumStack* stack) const {
  *stack = tr.total_internal_reflection ? c.itf.before : c.itf.after;
  return {tr.total_internal_reflection ? c.sp.point : c.far, glm::normalize(tr.dir)};
}

glm::dvec3 MapShader::transmitted(const Crossed& c, const glm::dvec3& dir, int depth, MapShadingStats* stats,
                                  KnownBlockers* known, uint64_t* trail) const {
  const SurfacePoint& sp = c.sp;
  const Transmission tr = transmission_between(dir, sp.geometric_normal, sp.shading_normal, c.itf.n_from, c.itf.n_to);
  if (options_.variant == MapVariant::envmap) {
    if (stats) ++stats->envmap_lookups;
    return envmap_at(envmap_direction(sp.point, glm::normalize(tr.dir)));
  }
  // Patow-Delrieux lens: entry from air to emergence in one paraxial transfer, no exit search.
  const int lens = lens_of_object_[sp.object];
  if (lens >= 0 && tr.entering && c.itf.before.empty()) {
    LensRay out;
    if (lens_transfer(lenses_[static_cast<size_t>(lens)], options_.refraction, sp.point, dir, &out)) {
      if (stats) ++stats->lens_transfers;
      return trace(out.point, out.dir, depth + 1, MediumStack{}, stats, known, nullptr, trail);
    }
    if (stats) ++stats->lens_fallbacks;
  }
  MediumStack stack;
  const Ray ray = transmitted_ray(c, tr, &stack);
  return trace(ray.origin, ray.dir, depth + 1, stack, stats, known, nullptr, trail);
}

std::vector<Ray> MapShader::transmitted_path(const glm::dvec3& origin, const glm::dvec3& dir, int max_rays) const {
  std::vector<Ray> path;
  Ray ray{origin, glm::normalize(dir)};
  MediumStack stack;
  while (static_cast<int>(path.size()) < max_rays) {
    const SearchResult r = search(ray.origin, ray.dir, stack, nullptr, false);  // answered now, whole
    if (!r.hit) break;
    const Crossed c = crossing_set(ray.origin, ray.dir, r, stack);
    if (c.itf.pass) {
      if (c.itf.after.passes > MEDIA_MAX_PASSES) break;
      ray.origin = c.far;
      stack = c.itf.after;
      continue;
    }
    if (!(scene_.materials[c.sp.material].transmit > 0.0)) break;
    const Transmission tr =
        transmission_between(ray.dir, c.sp.geometric_normal, c.sp.shading_normal, c.itf.n_from, c.itf.n_to);
    ray = transmitted_ray(c, tr, &stack);
    path.push_back(ray);
  }
  return path;
}

// The lookup direction of thesis 9.2: R, the bisector [[R + [[W]]]], or [[W]].
glm::dvec3 MapShader::envmap_direction(const glm::dvec3& w, const glm::dvec3& r) const {
  const glm::dvec3 wc = w - cube_.centre;
  const double len = glm::length(wc);
  const glm::dvec3 wu = len > 0.0 ? wc / len : r;
  switch (options_.lookup) {
    case EnvmapLookup::reflected: return r;
    case EnvmapLookup::bisector: {
      const glm::dvec3 b = r + wu;
      return glm::dot(b, b) > 1e-24 ? glm::normalize(b) : r;  // R = -[[W]]: no bisector
    }
    case EnvmapLookup::position: return wu;
  }
  return r;
}

// The map as a picture (Blinn & Newell): a texel's list resolved by Pack_Under_Mask, each
// fragment lit by local Phong and the shadow searches, seen from the centre. Computed on
// first lookup and kept (texel_state_: 0 not yet, 1 being computed, 2 done): the picture
// of all 6 N^2 texels, each with shadow walks of ~N texels, costs N^3 and is mostly never
// looked at (computed whole, it would dominate a render at large N).
glm::dvec3 MapShader::envmap_at(const glm::dvec3& direction) const {
  const int n = cube_.n;
  const CubeTexel t = direction_to_texel(direction, n);
  const size_t index =
      (static_cast<size_t>(t.face) * static_cast<size_t>(n) + static_cast<size_t>(t.j)) * static_cast<size_t>(n) +
      static_cast<size_t>(t.i);
  std::atomic<uint8_t>& state = texel_state_[index];
  uint8_t expected = 0;
  if (state.compare_exchange_strong(expected, 1, std::memory_order_acq_rel)) {
    env_colour_.faces[static_cast<size_t>(t.face)].set_rgb(t.i, t.j, glm::vec3(envmap_texel(t.face, t.i, t.j)));
    state.store(2, std::memory_order_release);
  } else {
    while (state.load(std::memory_order_acquire) != 2) std::this_thread::yield();
  }
  return glm::dvec3(env_colour_.faces[static_cast<size_t>(t.face)].rgb(t.i, t.j));
}

glm::dvec3 MapShader::envmap_texel(int face, int i, int j) const {
  const ABuffer& buffer = cube_.faces[static_cast<size_t>(face)];
  const FragmentShader shade_fragment = [&](const Fragment& f) {
    const glm::dvec3 p = fragment_point(buffer, *scene_.triangles, f, i, j);
    const SurfacePoint sp = surface_point(scene_, f.triangle(), p);
    const Material& m = scene_.materials[sp.material];
    const glm::dvec3 v = glm::normalize(cube_.centre - p);
    const glm::dvec3 nn = face_forward(sp.shading_normal, v);
    const glm::dvec3 od = diffuse_color_at(scene_, sp.triangle, p);
    return ShadedFragment{phong_ambient(m, scene_.ambient, od) + lights(sp, v, nn, od, nullptr, nullptr, nullptr),
                          m.opacity};
  };
  const SampleDepth depth{&buffer.view, &*scene_.triangles, i, j};
  return pack_under_mask(buffer.list(i, j), FULL_MASK, shade_fragment, *scene_.triangles, scene_.background, nullptr,
                         options_.exact_priority ? &depth : nullptr);
}

// Error_CP and Error_Parallax of one reflection ray against the exact tracer (thesis 9).
// The exact ray leaves the surface as every secondary ray of the tracer does (shading.hpp
// offset_origin), so that what it meets first is what the tracer's reflection meets.
void MapShader::measure(const SurfacePoint& sp, const glm::dvec3& r, const SearchResult* found,
                        const glm::dvec3* lookup, MapShadingStats* stats) const {
  RayErrors& e = stats->errors;
  const glm::dvec3& w = sp.point;
  const glm::dvec3 origin =
      offset_origin(w, sp.geometric_normal, r, self_intersection_offset(w, reference_->scene_scale()));
  Hit exact;
  const bool exact_hit = reference_->intersect(origin, r, &exact);
  const glm::dvec3 c = cube_.centre;
  // The method's found point X': the search's, or for a lookup the surface seen from C
  // in the lookup direction.
  bool has_point = false;
  glm::dvec3 x(0.0);
  uint32_t object = 0;
  if (found && found->hit) {
    has_point = true;
    x = found->point;
    object = found->object_id;
  } else if (lookup) {
    Hit seen;
    if (reference_->intersect(c, *lookup, &seen)) {
      has_point = true;
      x = seen.point;
      object = seen.object_id;
    }
  }
  if (!exact_hit) {
    if (has_point) ++e.false_hits;
    return;
  }
  const glm::dvec3 sigma = exact.point - c;
  if (lookup) {
    e.error_cp.add(error_cp(*lookup, sigma));
  } else if (has_point && glm::length(x - c) > 0.0) {
    e.error_cp.add(error_cp(x - c, sigma));
  } else {
    e.error_cp.add_miss();
  }
  if (has_point && glm::length(x - w) > 0.0) {
    e.error_parallax.add(error_parallax(x, w, r));
    if (object != exact.object_id) ++e.wrong_object;
  } else {
    e.error_parallax.add_miss();
  }
}

}  // namespace abcube
