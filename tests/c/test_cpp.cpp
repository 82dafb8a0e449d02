// The C header compiles as C++ (-Wall -Wextra -Wpedantic -Werror) and the RAII wrapper
// works: a match through it, and an error that becomes a shapecorr::Error.
#include <cmath>
#include <cstdio>
#include <cstring>

#include "shapecorr.hpp"

int main() {
    int failures = 0;
    try {
        shapecorr::Shape a = shapecorr::Shape::figure("star4", 0, 1500);
        shapecorr::Shape b = shapecorr::Shape::figure("star4", 2, 1500);
        shapecorr::Params params;
        params.set("k_max", 7).set("one_to_one", true);
        shapecorr::Correspondence c(a, b, &params);
        std::vector<std::uint32_t> ra = c.regions(SC_SIDE_A), rb = c.regions(SC_SIDE_B);
        auto matches = c.matches(SC_MATCHES_SYMMETRIC);
        std::size_t good = 0;
        for (std::size_t i = 0; i < ra.size(); i++)
            for (auto &m : matches)
                if (m.first == ra[i] && m.second == rb[i]) {
                    good++;
                    break;
                }
        double accuracy = double(good) / double(ra.size());
        std::printf("C++ wrapper: k = %u, %zu matches, symmetric accuracy %.3f\n", c.k(),
                    matches.size(), accuracy);
        if (c.k() < 5 || c.k() > 7 || accuracy < 0.85 || c.colors(SC_SIDE_B, SC_MATCHES_ONE_TO_ONE).size() != 4 * rb.size()) {
            std::printf("FAIL: unexpected result\n");
            failures++;
        }
        // The confidence is in [0, 1] or NaN; a warning exactly when it is doubtful.
        double confidence = c.confidence();
        std::optional<std::string> warning = c.warning();
        bool doubtful = !std::isnan(confidence) && confidence < SC_CONFIDENCE_DOUBTFUL_BELOW;
        std::printf("C++ wrapper: confidence %g%s%s\n", confidence, warning ? "; " : "",
                    warning ? warning->c_str() : "");
        if (!(std::isnan(confidence) || (confidence >= 0.0 && confidence <= 1.0)) ||
            warning.has_value() != doubtful || (warning && warning->empty())) {
            std::printf("FAIL: confidence %g with warning %s\n", confidence,
                        warning ? warning->c_str() : "(none)");
            failures++;
        }
        // The verdict: a hypothesis exactly when verified; the other answer is the runner-up.
        auto chosen = c.hypothesis(SC_ANSWER_CHOSEN), runner_up = c.hypothesis(SC_ANSWER_RUNNER_UP);
        auto other = c.other_answer();
        std::printf("C++ wrapper: hypothesis %s decided by %s, runner-up %s\n",
                    chosen ? chosen->c_str() : "(none)",
                    c.decided_by() ? c.decided_by()->c_str() : "(none)",
                    runner_up ? runner_up->c_str() : "(none)");
        if (chosen.has_value() == std::isnan(c.confidence()) ||
            c.decided_by().has_value() != chosen.has_value() ||
            other.has_value() != runner_up.has_value() ||
            (other && (other->hypothesis(SC_ANSWER_CHOSEN) != runner_up ||
                       other->decided_by() != std::optional<std::string>("other answer") ||
                       other->turn_degrees(SC_ANSWER_CHOSEN) != c.turn_degrees(SC_ANSWER_RUNNER_UP)))) {
            std::printf("FAIL: inconsistent verdict or other answer\n");
            failures++;
        }
    } catch (const shapecorr::Error &e) {
        std::printf("FAIL: %s\n", e.what());
        failures++;
    }
    try {
        // A landmark past the end of B fails the job before any work, naming the pair.
        shapecorr::Shape a = shapecorr::Shape::figure("star4", 0, 1500);
        shapecorr::Shape b = shapecorr::Shape::figure("star4", 2, 1500);
        shapecorr::Params params;
        params.set_landmarks({{3, 3}, {5, 99999}});
        shapecorr::Correspondence c(a, b, &params);
        std::printf("FAIL: no exception for a landmark out of range\n");
        failures++;
    } catch (const shapecorr::Error &e) {
        if (e.status() != SC_STATUS_INVALID_PARAMETER || std::strstr(e.what(), "pair 2") == nullptr) {
            std::printf("FAIL: wrong error %u: %s\n", unsigned(e.status()), e.what());
            failures++;
        }
    }
    try {
        shapecorr::Params params;
        params.set("no_such_option", 1);
        std::printf("FAIL: no exception for an unknown option\n");
        failures++;
    } catch (const shapecorr::Error &e) {
        if (e.status() != SC_STATUS_UNKNOWN_OPTION || std::strstr(e.what(), "no_such_option") == nullptr) {
            std::printf("FAIL: wrong error %u: %s\n", unsigned(e.status()), e.what());
            failures++;
        }
    }
    std::printf("C++ wrapper: %d failures\n", failures);
    return failures == 0 ? 0 : 1;
}
