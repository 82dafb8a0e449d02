// shapecorr.hpp: a thin header-only C++ (C++17) wrapper over shapecorr.h. Handles own their
// object (move-only, freed in the destructor); a failed call throws shapecorr::Error with the
// status code and sc_last_error()'s message. Everything else is the C API.
#ifndef SHAPECORR_HPP
#define SHAPECORR_HPP

#include <cstdint>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "shapecorr.h"

namespace shapecorr {

// A failed call: status() is the sc_status, what() the library's message.
class Error : public std::runtime_error {
  public:
    Error(sc_status status, const std::string &message)
        : std::runtime_error(message), status_(status) {}
    sc_status status() const noexcept { return status_; }

  private:
    sc_status status_;
};

inline void check(sc_status status) {
    if (status != SC_STATUS_OK)
        throw Error(status, std::string(sc_status_str(status)) + ": " + sc_last_error());
}

namespace detail {
struct ShapeFree { void operator()(sc_shape *p) const noexcept { sc_shape_free(p); } };
struct ParamsFree { void operator()(sc_params *p) const noexcept { sc_params_free(p); } };
struct CorrespondenceFree {
    void operator()(sc_correspondence *p) const noexcept { sc_correspondence_free(p); }
};
}  // namespace detail

// A shape (immutable; safe to share between threads).
class Shape {
  public:
    static Shape mesh(const std::vector<double> &xyz, const std::vector<std::uint32_t> &triangles) {
        sc_shape *p = nullptr;
        check(sc_shape_new_mesh(xyz.data(), xyz.size() / 3, triangles.data(), triangles.size() / 3, &p));
        return Shape(p);
    }
    static Shape point_cloud(const std::vector<double> &xyz) {
        sc_shape *p = nullptr;
        check(sc_shape_new_point_cloud(xyz.data(), xyz.size() / 3, &p));
        return Shape(p);
    }
    static Shape read(const std::string &path, bool as_point_cloud = false) {
        sc_shape *p = nullptr;
        check(sc_shape_read(path.c_str(), as_point_cloud, &p));
        return Shape(p);
    }
    static Shape figure(const std::string &kind, std::uint32_t pose, std::uint32_t vertices) {
        sc_shape *p = nullptr;
        check(sc_shape_new_figure(kind.c_str(), pose, vertices, &p));
        return Shape(p);
    }
    std::size_t n_vertices() const { return sc_shape_n_vertices(get()); }
    const sc_shape *get() const noexcept { return ptr_.get(); }

  private:
    explicit Shape(sc_shape *p) : ptr_(p) {}
    std::unique_ptr<sc_shape, detail::ShapeFree> ptr_;
};

// Parameters (defaults as documented; set options by name).
class Params {
  public:
    Params() {
        sc_params *p = nullptr;
        check(sc_params_new(&p));
        ptr_.reset(p);
    }
    Params &set(const char *name, std::int64_t v) { check(sc_params_set_int(ptr_.get(), name, v)); return *this; }
    Params &set(const char *name, int v) { return set(name, static_cast<std::int64_t>(v)); }
    Params &set(const char *name, double v) { check(sc_params_set_double(ptr_.get(), name, v)); return *this; }
    Params &set(const char *name, bool v) { check(sc_params_set_bool(ptr_.get(), name, v)); return *this; }
    // Landmark pairs (vertex of A, vertex of B), replacing those set before; checked against
    // the shapes when a job starts.
    Params &set_landmarks(const std::vector<std::pair<std::uint32_t, std::uint32_t>> &pairs) {
        std::vector<std::uint32_t> flat;
        for (const auto &p : pairs) {
            flat.push_back(p.first);
            flat.push_back(p.second);
        }
        check(sc_params_set_landmarks(ptr_.get(), flat.data(), pairs.size()));
        return *this;
    }
    const sc_params *get() const noexcept { return ptr_.get(); }

  private:
    std::unique_ptr<sc_params, detail::ParamsFree> ptr_;
};

// The region correspondence between two shapes (immutable; safe to share between threads).
class Correspondence {
  public:
    Correspondence(const Shape &a, const Shape &b, const Params *params = nullptr,
                   sc_progress_callback progress = nullptr, void *userdata = nullptr) {
        sc_correspondence *p = nullptr;
        check(sc_match(a.get(), b.get(), params ? params->get() : nullptr, progress, userdata, &p));
        ptr_.reset(p);
    }
    std::uint32_t k() const { return sc_correspondence_k(ptr_.get()); }
    std::vector<std::uint32_t> regions(std::uint32_t side) const {
        std::vector<std::uint32_t> out(sc_correspondence_n_vertices(ptr_.get(), side));
        check(sc_correspondence_regions(ptr_.get(), side, out.data(), out.size()));
        return out;
    }
    // Pairs (region of A, region of B) of a kind (SC_MATCHES_SYMMETRIC or _ONE_TO_ONE).
    std::vector<std::pair<std::uint32_t, std::uint32_t>> matches(std::uint32_t kind) const {
        std::vector<std::uint32_t> flat(2 * sc_correspondence_n_matches(ptr_.get(), kind));
        check(sc_correspondence_matches(ptr_.get(), kind, flat.data(), flat.size()));
        std::vector<std::pair<std::uint32_t, std::uint32_t>> out;
        for (std::size_t i = 0; i + 1 < flat.size(); i += 2)
            out.emplace_back(flat[i], flat[i + 1]);
        return out;
    }
    // RGBA bytes per vertex of one side, coloured by the matches of a kind.
    std::vector<std::uint8_t> colors(std::uint32_t side, std::uint32_t kind) const {
        std::vector<std::uint8_t> out(4 * sc_correspondence_n_vertices(ptr_.get(), side));
        check(sc_correspondence_colors(ptr_.get(), side, kind, out.data(), out.size()));
        return out;
    }
    // The confidence of the one-to-one answer in [0, 1]; NaN when it was not verified.
    double confidence() const { return sc_correspondence_confidence(ptr_.get()); }
    // What to tell the user when the answer is doubtful (confidence below
    // SC_CONFIDENCE_DOUBTFUL_BELOW); nothing otherwise.
    std::optional<std::string> warning() const {
        const char *text = sc_correspondence_warning(ptr_.get());
        if (text == nullptr)
            return std::nullopt;
        return std::string(text);
    }
    // The name of hypothesis `which` (SC_ANSWER_CHOSEN or SC_ANSWER_RUNNER_UP); nothing when
    // the answer was not verified or there is no runner-up.
    std::optional<std::string> hypothesis(std::uint32_t which) const {
        const char *name = sc_correspondence_hypothesis(ptr_.get(), which);
        if (name == nullptr)
            return std::nullopt;
        return std::string(name);
    }
    // Its cost and the turn (degrees) its map implies; NaN when there is none.
    double hypothesis_cost(std::uint32_t which) const {
        return sc_correspondence_hypothesis_cost(ptr_.get(), which);
    }
    double turn_degrees(std::uint32_t which) const {
        return sc_correspondence_turn_degrees(ptr_.get(), which);
    }
    // What settled the choice ("cost", "close call", "placement", "landmarks", "other
    // answer"); nothing when the answer was not verified.
    std::optional<std::string> decided_by() const {
        const char *name = sc_correspondence_decided_by(ptr_.get());
        if (name == nullptr)
            return std::nullopt;
        return std::string(name);
    }
    bool placement_used() const { return sc_correspondence_placement_used(ptr_.get()); }
    // The runner-up's answer (nothing recomputed); nothing when there is no runner-up.
    std::optional<Correspondence> other_answer() const {
        if (sc_correspondence_hypothesis(ptr_.get(), SC_ANSWER_RUNNER_UP) == nullptr)
            return std::nullopt;
        sc_correspondence *p = nullptr;
        check(sc_correspondence_other_answer(ptr_.get(), &p));
        return Correspondence(p);
    }
    const sc_correspondence *get() const noexcept { return ptr_.get(); }

  private:
    explicit Correspondence(sc_correspondence *p) : ptr_(p) {}
    std::unique_ptr<sc_correspondence, detail::CorrespondenceFree> ptr_;
};

}  // namespace shapecorr

#endif  // SHAPECORR_HPP
