// mmvk.Database, mmvk.Animation and mmvk.build(): the database and its
// arrays, viewed without a copy.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "arrays.hpp"
#include "bindings.hpp"
#include "errors.hpp"
#include "mmvk/database/database.hpp"
#include "mmvk/database/database_build.hpp"
#include "mmvk/database/database_io.hpp"
#include "mmvk/common/file_io.hpp"
#include "mmvk/common/json_check.hpp"
#include "mmvk/database/manifest.hpp"
#include "mmvk/common/thread_pool.hpp"

namespace mmvk::python {

namespace py = pybind11;

namespace {

// glm's vectors and quaternions are plain floats in memory (quaternions x,
// y, z, w), so their arrays are viewed as float arrays.
static_assert(sizeof(glm::vec3) == 3 * sizeof(float));
static_assert(sizeof(glm::quat) == 4 * sizeof(float));

const Database& database_of(const py::handle& self) { return self.cast<const Database&>(); }

std::vector<std::string> tag_list(const Database& db, TagMask mask) {
  std::vector<std::string> names;
  for (std::size_t t = 0; t < db.tag_names().size(); ++t) {
    if (mask & (TagMask{1} << t)) names.push_back(db.tag_names()[t]);
  }
  return names;
}

py::list channel_list(const Database& db) {
  py::list out;
  const FeatureSchema& schema = db.schema();
  for (std::size_t c = 0; c < schema.channels.size(); ++c) {
    const FeatureChannel& ch = schema.channels[c];
    py::dict d;
    d["name"] = ch.name;
    d["kind"] = std::string(channel_kind_name(ch.kind));
    d["offset"] = schema.offset(c);
    d["dims"] = ch.dims();
    d["weight"] = ch.weight;
    d["normalization"] = std::string(normalization_name(ch.normalization));
    d["bone"] = ch.bone;
    d["second_bone"] = ch.second_bone;
    d["offsets_seconds"] = ch.offsets_seconds;
    out.append(d);
  }
  return out;
}

py::list clip_list(const Database& db) {
  py::list out;
  for (const Clip& clip : db.clips()) {
    py::dict d;
    d["name"] = clip.name;
    d["source"] = clip.source;
    d["tags"] = tag_list(db, clip.tags);
    d["loop"] = clip.loop;
    d["mirrored"] = clip.mirrored;
    d["cost_multiplier"] = clip.cost_multiplier;
    d["cost_bias"] = clip.cost_bias;
    d["first_frame"] = clip.first_frame;
    d["frame_count"] = clip.frame_count;
    out.append(d);
  }
  return out;
}

// raw = normalized * scale + offset, row by row: the inverse of
// Database::normalize.
py::array raw_features(const Database& db, const py::handle& features) {
  const FloatRows in = float_rows(features, db.dims(), "features");
  py::array_t<float> out(py::array(in.keep).request().shape);
  float* o = out.mutable_data();
  const auto norm = db.normalization();
  for (std::size_t r = 0; r < in.rows; ++r) {
    for (std::uint32_t d = 0; d < db.dims(); ++d) {
      const std::size_t i = r * db.dims() + d;
      o[i] = in.values[i] * norm[d].scale + norm[d].offset;
    }
  }
  return out;
}

py::array normalized_features(const Database& db, const py::handle& raw) {
  const FloatRows in = float_rows(raw, db.dims(), "raw");
  py::array_t<float> out(py::array(in.keep).request().shape);
  float* o = out.mutable_data();
  for (std::size_t r = 0; r < in.rows; ++r) {
    db.normalize(in.values.subspan(r * db.dims(), db.dims()), {o + r * db.dims(), db.dims()});
  }
  return out;
}

// `text` parsed with the library's checks (mmvk/common/json_check.hpp: duplicate
// keys, bytes after the value, nesting depth), so that the merge path below
// refuses what build(path) and `mmvk build` refuse, and never walks or
// dumps a document nested deeply enough to overflow the stack.
nlohmann::json strict_json(const std::string& text, const std::string& source) {
  check(check_json_text(text, source));
  nlohmann::json parsed = nlohmann::json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (parsed.is_discarded()) raise(source + ": not valid JSON");  // unreachable after the check
  return parsed;
}

// The manifest JSON with `fields` set over its top-level fields.
std::string merged_manifest(const std::string& text, const nlohmann::json& fields, const std::string& source) {
  nlohmann::json manifest = strict_json(text, source);
  if (!manifest.is_object()) {
    raise(source + ": not a JSON object, so the fields given to build() cannot be added to it");
  }
  for (const auto& [key, value] : fields.items()) manifest[key] = value;
  // A path that is not UTF-8 is replaced (and then not found, naming it)
  // instead of throwing from the dump.
  return manifest.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

// A dict (the manifest fields, a manifest or schema dict) as JSON text. A
// float that JSON cannot hold (nan, inf) is named first: JSON has no
// spelling for it, and json.dumps would write one that no parser reads.
std::string dict_json(const py::handle& dict, const std::string& what) {
  for (const auto& [key, value] : py::reinterpret_borrow<py::dict>(dict)) {
    if (py::isinstance<py::float_>(value) && !std::isfinite(value.cast<double>())) {
      raise(std::string(py::str(key)) + ": expected a finite number, got " + std::string(py::str(value)));
    }
  }
  try {
    return py::str(py::module_::import("json").attr("dumps")(dict, py::arg("allow_nan") = false)).cast<std::string>();
  } catch (py::error_already_set& e) {
    if (!e.matches(PyExc_ValueError) && !e.matches(PyExc_TypeError)) throw;
    raise(what + ": " + std::string(py::str(e.value())));  // a nested nan, or a value JSON cannot hold
  }
}

// mmvk.build: `source` a manifest file, a folder of BVH or a manifest dict;
// `schema` a schema file or dict; `fields` manifest fields over the source's.
std::shared_ptr<Database> build(const py::object& source, const py::object& schema, const py::kwargs& kwargs) {
  nlohmann::json fields = strict_json(dict_json(kwargs, "the manifest fields"), "the manifest fields");
  if (!schema.is_none()) {
    if (py::isinstance<py::dict>(schema)) {
      fields["schema"] = strict_json(dict_json(schema, "schema"), "schema");
    } else {
      fields["schema"] = std::filesystem::absolute(to_path(schema, "schema")).string();
    }
  }
  Manifest manifest;
  if (py::isinstance<py::dict>(source)) {
    const std::string text = dict_json(source, "source");
    manifest = take(parse_manifest_json(merged_manifest(text, fields, "the manifest dict"), "the manifest dict",
                                        std::filesystem::current_path()));
  } else {
    const std::filesystem::path path = to_path(source, "source");
    const ErrorKind kind = kind_for_input(path);
    std::error_code ec;
    if (fields.empty()) {
      manifest = take(load_manifest_or_directory(path), kind);
    } else if (std::filesystem::is_directory(path, ec) || is_motion_path(path)) {
      // A folder's (or a motion file's) manifest as JSON, so that the fields
      // are read by the manifest's own parser (and named in its errors).
      const Manifest listed = take(load_manifest_or_directory(path), kind);
      nlohmann::json clips = nlohmann::json::array();
      for (const ManifestClip& clip : listed.clips) {
        clips.push_back({{"file", std::filesystem::absolute(clip.file).string()}});
      }
      const std::string text = nlohmann::json{{"clips", clips}}.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
      manifest = take(parse_manifest_json(merged_manifest(text, fields, path.string()), path.string(), path));
    } else {
      ReadOptions options;
      options.max_bytes = kMaxJsonBytes;
      const std::string text = take(read_file(path, options), kind);
      manifest = take(parse_manifest_json(merged_manifest(text, fields, path.string()), path.string(),
                                          path.parent_path()));
    }
  }
  Result<Database> built = make_error("");
  {
    py::gil_scoped_release released;
    ThreadPool pool(0);
    BuildOptions options;
    options.pool = &pool;
    built = build_database(manifest, options);
  }
  return std::make_shared<Database>(take(std::move(built)));
}

// The animation section, viewed through its Database.
struct AnimationView {
  py::object owner;  // the Database
  const AnimationData* data = nullptr;
};

void bind_animation(py::module_& m) {
  py::class_<AnimationView>(m, "Animation",
                            "The animation section of a Database: the skeleton and, per database frame, the pose "
                            "(character space), the character root and the foot contacts. Arrays are read-only "
                            "views of the database's memory.")
      .def_property_readonly("joint_names", [](const AnimationView& a) { return a.data->skeleton.names; },
                             "Joint names, [joints].")
      .def_property_readonly(
          "parents",
          [](const AnimationView& a) {
            // A read-only view like the other arrays (it was a writable copy).
            return view(a.owner, a.data->skeleton.parents.data(), {py::ssize_t(a.data->skeleton.parents.size())});
          },
          "Parent of each joint, int32 [joints], -1 for the root; parents[i] < i.")
      .def_property_readonly(
          "rest_offsets",
          [](const AnimationView& a) {
            return view(a.owner, reinterpret_cast<const float*>(a.data->skeleton.rest_offsets.data()),
                        {py::ssize_t(a.data->joint_count()), 3});
          },
          "Rest offsets, float32 [joints x 3], metres, in the parent's frame.")
      .def_property_readonly(
          "rotations",
          [](const AnimationView& a) {
            return view(a.owner, reinterpret_cast<const float*>(a.data->local_rotations.data()),
                        {py::ssize_t(a.data->frame_count), py::ssize_t(a.data->joint_count()), 4});
          },
          "Local joint rotations, float32 [frames x joints x 4], unit quaternions (x, y, z, w); the hips in "
          "character space.")
      .def_property_readonly(
          "translated_joints",
          [](const AnimationView& a) {
            return view(a.owner, a.data->translated_joints.data(), {py::ssize_t(a.data->translated_joints.size())});
          },
          "The joints whose translation varies per frame, uint32 [T].")
      .def_property_readonly(
          "translations",
          [](const AnimationView& a) {
            return view(a.owner, reinterpret_cast<const float*>(a.data->local_translations.data()),
                        {py::ssize_t(a.data->frame_count), py::ssize_t(a.data->translated_joints.size()), 3});
          },
          "Local translations of translated_joints, float32 [frames x T x 3], metres.")
      .def_property_readonly(
          "root_positions",
          [](const AnimationView& a) {
            return view(a.owner, reinterpret_cast<const float*>(a.data->root_positions.data()),
                        {py::ssize_t(a.data->frame_count), 3});
          },
          "Character root per frame, float32 [frames x 3], metres, y = 0 (the clip's world space).")
      .def_property_readonly(
          "root_yaws",
          [](const AnimationView& a) { return view(a.owner, a.data->root_yaws.data(), {py::ssize_t(a.data->frame_count)}); },
          "Character root facing per frame, float32 [frames], radians about +Y (0 faces +Z).")
      .def_property_readonly(
          "contacts",
          [](const AnimationView& a) { return view(a.owner, a.data->contacts.data(), {py::ssize_t(a.data->frame_count)}); },
          "Foot contact bits per frame, uint8 [frames]: 1 left planted, 2 right planted, 4 left heel, 8 left toe, "
          "16 right heel, 32 right toe.")
      .def_property_readonly("contact_joints",
                             [](const AnimationView& a) { return py::make_tuple(a.data->contact_joints[0], a.data->contact_joints[1]); },
                             "The joints (left, right) whose contact is detected (the toes, else the heels); -1 when none.")
      .def("__repr__", [](const AnimationView& a) {
        return "<mmvk.Animation: " + std::to_string(a.data->joint_count()) + " joints, " +
               std::to_string(a.data->frame_count) + " frames>";
      });
}

// Database.load and .save.
void add_files(py::class_<Database, std::shared_ptr<Database>>& database) {
  database
      .def_static(
          "load",
          [](const py::object& path) {
            const std::filesystem::path p = to_path(path, "path");
            Result<Database> loaded = make_error("");
            {
              py::gil_scoped_release released;
              loaded = load_database(p);
            }
            return std::make_shared<Database>(take(std::move(loaded), kind_for_input(p)));
          },
          py::arg("path"), "Loads an .mmdb file. Raises OSError when it cannot be read, ValueError when it is not a valid database.")
      .def(
          "save",
          [](const Database& db, const py::object& path) {
            const std::filesystem::path p = to_path(path, "path");
            Status saved;
            {
              py::gil_scoped_release released;
              saved = save_database(db, p);
            }
            check(saved, ErrorKind::OS);
          },
          py::arg("path"), "Writes the database to an .mmdb file (atomically: a failed save leaves any old file). Raises OSError.");
}

// Frames, dims and fps.
void add_sizes(py::class_<Database, std::shared_ptr<Database>>& database) {
  database
      .def_property_readonly("frame_count", &Database::frame_count, "Frames (rows of features).")
      .def_property_readonly("dims", &Database::dims, "Feature dimensions (columns of features).")
      .def_property_readonly("fps", &Database::fps, "Frames per second.")
      .def("__len__", &Database::frame_count);
}

// Per-frame arrays: read-only views of the database's memory.
void add_frame_arrays(py::class_<Database, std::shared_ptr<Database>>& database) {
  database
      .def_property_readonly(
          "features",
          [](const py::object& self) {
            const Database& db = database_of(self);
            return view(self, db.features().data(), {py::ssize_t(db.frame_count()), py::ssize_t(db.dims())});
          },
          "The normalized feature matrix, float32 [frames x dims], a read-only view of the database's memory (no copy).")
      .def_property_readonly(
          "frame_flags",
          [](const py::object& self) {
            const Database& db = database_of(self);
            return view(self, db.frame_flags().data(), {py::ssize_t(db.frame_count())});
          },
          "Per-frame flags, uint32 [frames]: 1 do_not_use, 2 block_transition, 4 edge_excluded.")
      .def_property_readonly(
          "frame_tags",
          [](const py::object& self) {
            const Database& db = database_of(self);
            return view(self, db.frame_tags().data(), {py::ssize_t(db.frame_count())});
          },
          "Per-frame tag masks, uint64 [frames]: bit t = tags[t].")
      .def_property_readonly(
          "frame_clip",
          [](const py::object& self) {
            const Database& db = database_of(self);
            return view(self, db.frame_clip().data(), {py::ssize_t(db.frame_count())});
          },
          "The clip of each frame, uint32 [frames] (an index into clips).");
}

// Tags, channels, clips, the schema, the animation, normalization and the repr.
void add_description(py::class_<Database, std::shared_ptr<Database>>& database) {
  database
      .def_property_readonly(
          "tags", [](const Database& db) { return std::vector<std::string>(db.tag_names().begin(), db.tag_names().end()); },
          "Tag names; tag t is bit t of frame_tags.")
      .def_property_readonly("channels", &channel_list,
                             "The feature schema's channels in layout order: dicts with name, kind, offset, dims, "
                             "weight, normalization, bone, second_bone, offsets_seconds.")
      .def_property_readonly("clips", &clip_list,
                             "The clips in frame order: dicts with name, source, tags, loop, mirrored, "
                             "cost_multiplier, cost_bias, first_frame, frame_count.")
      .def_property_readonly(
          "dim_names",
          [](const Database& db) {
            std::vector<std::string> names;
            for (std::uint32_t d = 0; d < db.dims(); ++d) names.push_back(db.schema().dim_name(d));
            return names;
          },
          "The name of each feature dimension, e.g. 'trajectory_position[1].z'.")
      .def_property_readonly("schema_json", [](const Database& db) { return schema_to_json(db.schema()); },
                             "The feature schema as JSON text (docs/database.md).")
      .def_property_readonly("content_hash", &Database::content_hash, "A 64-bit digest of the search content.")
      .def_property_readonly(
          "animation",
          [](const py::object& self) -> py::object {
            const Database& db = database_of(self);
            if (!db.animation()) return py::none();
            return py::cast(AnimationView{self, db.animation()});
          },
          "The Animation (skeleton, poses, root, contacts), or None for a database built without it.")
      .def(
          "raw", [](const Database& db, const py::object& features) { return raw_features(db, features); },
          py::arg("features"),
          "Raw feature values (metres, m/s, ...) of normalized rows: float32 [B x dims] (or [dims]) in, the same shape out.")
      .def(
          "normalize", [](const Database& db, const py::object& raw) { return normalized_features(db, raw); },
          py::arg("raw"),
          "Normalizes raw feature rows with the database's offsets and scales: float32 [B x dims] (or [dims]) in, the same shape out.")
      .def("__repr__", [](const Database& db) {
        return "<mmvk.Database: " + std::to_string(db.frame_count()) + " frames, " + std::to_string(db.dims()) +
               " dims, " + std::to_string(db.clips().size()) + " clips>";
      });
}

}  // namespace

void bind_database(py::module_& m) {
  bind_animation(m);
  py::class_<Database, std::shared_ptr<Database>> database(
      m, "Database",
      "A motion matching database: the normalized feature matrix, its normalization, clips, tags, per-frame flags "
      "and (unless built without) the animation. Immutable. Made by mmvk.build() or Database.load().");
  add_files(database);
  add_sizes(database);
  add_frame_arrays(database);
  add_description(database);

  m.def("build", &build, py::arg("source"), py::arg("schema") = py::none(),
        "build(source, schema=None, **manifest_fields) -> Database\n\n"
        "Builds a database from BVH motion capture. source: a manifest JSON file, a folder of BVH files, or a "
        "manifest as a dict (relative paths from the working directory). schema: a schema JSON file or dict "
        "(default: the manifest's, else the 27-d default set). manifest_fields: top-level manifest fields set over "
        "the source's, e.g. fps=30, mirror=True, edge_rule='extrapolate' (docs/database.md). Runs on all cores "
        "with the GIL released. Raises OSError for a missing source, ValueError with the library's message otherwise.");
}

}  // namespace mmvk::python
