// A ros2_control-style hardware interface over servobus, without ROS: the
// controller manager's cycle is read() (every joint's state), update (here a
// ramp), write() (every joint's command). write() sends the setpoints and the
// next Sync Monitor in one burst; read() takes its answers.
//
//   sb_ros2_cycle HOST:PORT [--clock FILE] [--ids ID,ID,...] [--seconds S] [--period-ms MS]
//   (--ids: default 1; --seconds: 1; --period-ms: 10)
//
// Exit 0 when nine states in ten or more came and each joint ends within 1
// degree of its command, kept within its angle limits; a joint resting
// outside them is refused, exit 1 (tools/tests/test_servobus_examples.py
// runs it against servo_sim).
#include <algorithm>
#include <climits>
#include <cmath>
#include <cstdint>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <thread>
#include <vector>

#include "servobus/servobus_posix.h"
#include "examples/sb_sim_clock.h"

namespace {

constexpr double kDeciDegPerRad = 1800.0 / M_PI;

std::string text(const sb_error &e)
{
    char buf[256];
    sb_error_text(&e, buf, sizeof buf);
    return buf;
}

class ServoBusHardware {
  public:
    bool on_init(const std::string &host, unsigned port, const std::vector<uint8_t> &ids, uint16_t period_ms,
                 bool sim_clock)
    {
        int rc = sb_tcp_open(&link_, host.c_str(), port);
        if (rc != 0) {
            std::fprintf(stderr, "sb_ros2_cycle: cannot connect to %s:%u (errno %d: %s)%s\n", host.c_str(), port, -rc,
                         std::strerror(-rc), rc == -EBUSY ? ": another program holds the bus, close it first" : "");
            return false;
        }
        sb_transport t = sb_posix_transport(&link_);
        if (sim_clock)
            t.now_us = sim_clock_us;
        sb_bus_init(&bus_, t, 115200);
        ids_ = ids;
        position_.assign(ids.size(), 0.0);
        velocity_.assign(ids.size(), 0.0);
        command_.assign(ids.size(), 0.0);
        got_.assign(ids.size(), 0);
        low_.assign(ids.size(), INT32_MIN);
        high_.assign(ids.size(), INT32_MAX);
        states_.resize(ids.size());
        sb_error e = sb_loop_init(&loop_, &bus_, ids_.data(), ids_.size(), period_ms);
        if (e.status != SB_OK && e.field != nullptr && std::strcmp(e.field, "period_ms") == 0 && e.least > 1)
            std::fprintf(stderr,
                         "sb_ros2_cycle: a cycle of %zu joint(s) is %zu bytes on the wire, %.2f ms at %u baud\n",
                         ids_.size(), sb_cycle_bytes(ids_.size()), 1000.0 / sb_wire_limit_hz(ids_.size(), 115200),
                         115200u);
        return check(e);
    }

    // Every joint answers, within its angle limits; commands start where
    // the joints are. The servo clamps a streamed setpoint into its limits
    // (items 48, 51, 52), so a stream begun outside them would throw the
    // horn to the nearest at full speed: such a joint is refused here.
    bool on_activate()
    {
        for (size_t k = 0; k < ids_.size(); k++) {
            sb_ping_request p = {ids_[k]};
            sb_ping_answer a;
            if (!check(sb_call_ping(&bus_, &p, &a)) || !read_limits(k))
                return false;
        }
        bool got[SB_MAX_SERVOS];
        if (!check(sb_sync_monitor(&bus_, ids_.data(), ids_.size(), states_.data(), got)))
            return false;
        for (size_t k = 0; k < ids_.size(); k++) {
            int32_t at = states_[k].angle;
            if (at < low_[k] || at > high_[k]) {
                std::fprintf(stderr,
                             "sb_ros2_cycle: servo %u is at %.1f deg, outside its angle limits %.1f..%.1f deg "
                             "(angle_min, angle_max, angle_limit_on): a setpoint there would be clamped into "
                             "them, a jump at full speed. Move it within them first (servoctl move %u %.1f "
                             "--velocity 45 --multi-turn: from where it reads, a turn and more), or change the "
                             "limits\n",
                             ids_[k], at / 10.0, low_[k] / 10.0, high_[k] / 10.0, ids_[k],
                             (at < low_[k] ? low_[k] : high_[k]) / 10.0);
                return false;
            }
            command_[k] = position_[k] = at / kDeciDegPerRad;
        }
        return true;
    }

    // A command within joint k's angle limits (radians): a ramp past one
    // stops there, as the servo would hold it.
    double within(size_t k, double rad) const
    {
        return std::min(std::max(rad, low_[k] / kDeciDegPerRad), high_[k] / kDeciDegPerRad);
    }

    // The joints' states: the answers to the Sync Monitor the last write()
    // sent (or one sent now, on the first cycle).
    bool read()
    {
        bool got[SB_MAX_SERVOS];
        sb_error e = pending_ ? sb_sync_monitor_answers(&bus_, ids_.data(), ids_.size(), states_.data(), got)
                              : sb_sync_monitor(&bus_, ids_.data(), ids_.size(), states_.data(), got);
        pending_ = false;
        for (size_t k = 0; k < ids_.size(); k++) {
            if (!got[k]) {
                missed_++;
                continue;
            }
            double was = position_[k];
            position_[k] = states_[k].angle / kDeciDegPerRad;
            velocity_[k] = (position_[k] - was) * 1000.0 / loop_.stream.period_ms;
            got_[k]++;
        }
        return e.status == SB_OK || e.status == SB_E_NO_ANSWER || check(e);
    }

    // The commands, and the next Sync Monitor behind them, in one write.
    bool write()
    {
        int32_t angles[SB_MAX_SERVOS];
        size_t len = 0;
        for (size_t k = 0; k < ids_.size(); k++)
            angles[k] = static_cast<int32_t>(std::lround(command_[k] * kDeciDegPerRad));
        // Stamped now: the controller's command is for this moment.
        sb_error e = sb_stream_frame_at(&loop_.stream, angles, nullptr, static_cast<uint32_t>(now_us() / 1000u),
                                        bus_.tx, sizeof bus_.tx - loop_.monitor_len, &len);
        if (!check(e))
            return false;
        std::memcpy(bus_.tx + len, loop_.monitor, loop_.monitor_len);
        pending_ = check(sb_send(&bus_, bus_.tx, len + loop_.monitor_len));
        return pending_;
    }

    uint64_t now_us() { return bus_.t.now_us(bus_.t.ctx); }
    std::vector<double> &command() { return command_; }
    const std::vector<double> &position() const { return position_; }
    unsigned missed() const { return missed_; }
    ~ServoBusHardware() { sb_posix_close(&link_); }

  private:
    // Joint k's angle limits (0.1 deg); off: no limit but the stream's range.
    bool read_limits(size_t k)
    {
        int64_t v[3];
        const uint8_t items[3] = {SB_ITEM_ANGLE_LIMIT_ON, SB_ITEM_ANGLE_MIN_DECIDEG, SB_ITEM_ANGLE_MAX_DECIDEG};
        for (int i = 0; i < 3; i++) {
            sb_read_data_request r = {ids_[k], items[i]};
            sb_read_data_answer a;
            if (!check(sb_call_read_data(&bus_, &r, &a)))
                return false;
            v[i] = a.data;
        }
        low_[k] = v[0] ? static_cast<int32_t>(v[1]) : INT32_MIN;
        high_[k] = v[0] ? static_cast<int32_t>(v[2]) : INT32_MAX;
        return true;
    }

    bool check(const sb_error &e)
    {
        if (e.status == SB_OK)
            return true;
        std::fprintf(stderr, "servobus: %s\n", text(e).c_str());
        return false;
    }

    sb_posix link_{};
    sb_bus bus_{};
    sb_loop loop_{};
    std::vector<uint8_t> ids_;
    std::vector<double> position_, velocity_, command_;
    std::vector<unsigned> got_;
    std::vector<int32_t> low_, high_;
    std::vector<sb_monitor_answer> states_;
    bool pending_ = false;
    unsigned missed_ = 0;
};

} // namespace

// A whole number within least..most, or -1.
static long whole(const std::string &s, long least, long most)
{
    char *end = nullptr;
    if (s.empty() || s[0] < '0' || s[0] > '9')
        return -1;
    long n = std::strtol(s.c_str(), &end, 10);
    return *end == '\0' && n >= least && n <= most ? n : -1;
}

static int refuse(const char *opt, const std::string &val, const char *what)
{
    std::fprintf(stderr, "sb_ros2_cycle: %s: '%s' is not %s\n", opt, val.c_str(), what);
    return 2;
}

static int usage(const char *self)
{
    std::fprintf(stderr, "usage: %s [socket://]HOST:PORT [--clock FILE] [--ids ID,ID,...] [--seconds S] [--period-ms MS]\n"
                         "  --ids: default 1; --seconds: 1; --period-ms: 10\n", self);
    return 2;
}

int main(int argc, char **argv)
{
    if (argc < 2 || std::strchr(argv[1], ':') == nullptr || argc % 2 != 0) {
        return usage(argv[0]);
    }
    std::string where = argv[1];
    if (where.compare(0, 9, "socket://") == 0) // as servoctl sim and servo_sim print it
        where = where.substr(9);
    std::string host = where.substr(0, where.rfind(':'));
    long port_n = whole(where.substr(where.rfind(':') + 1), 1, 65535);
    if (port_n < 0)
        return refuse("address", argv[1], "HOST:PORT (a port 1-65535)");
    unsigned port = static_cast<unsigned>(port_n);
    std::vector<uint8_t> ids = {1};
    double seconds = 1.0;
    uint16_t period_ms = 10;
    bool sim = false;
    for (int k = 2; k + 1 < argc; k += 2) {
        std::string opt = argv[k], val = argv[k + 1];
        if (opt == "--clock") {
            sim = sim_clock_open(val.c_str()) == 0;
            if (!sim) {
                std::fprintf(stderr, "sb_ros2_cycle: --clock: %s %s\n", val.c_str(), sim_clock_why(sim_clock_last()));
                return 2;
            }
        } else if (opt == "--ids") {
            ids.clear();
            for (size_t at = 0; at <= val.size();) { // every ID between commas: none empty
                size_t comma = std::min(val.find(',', at), val.size());
                std::string tok = val.substr(at, comma - at);
                long id = whole(tok, 0, SB_MAX_ID); // 255 is broadcast: no joint answers it
                if (id < 0) {
                    std::fprintf(stderr, "sb_ros2_cycle: --ids: '%s' is not a servo ID (0-%u) in '%s'\n", tok.c_str(),
                                 SB_MAX_ID, val.c_str());
                    return 2;
                }
                ids.push_back(static_cast<uint8_t>(id));
                at = comma + 1;
            }
        } else if (opt == "--seconds") {
            char *end = nullptr;
            seconds = std::strtod(val.c_str(), &end);
            if (val.empty() || *end != '\0' || !(seconds > 0.0 && seconds <= 3600.0))
                return refuse("--seconds", val, "a time in seconds (above 0, at most 3600)");
        } else if (opt == "--period-ms") {
            long n = whole(val, 1, 1000); // a stream's period: item 69's range, but for its 0 (off)
            if (n < 0)
                return refuse("--period-ms", val, "a period of 1-1000 ms");
            period_ms = static_cast<uint16_t>(n);
        } else {
            return usage(argv[0]);
        }
    }
    if (ids.empty()) {
        return usage(argv[0]);
    }
    if (seconds * 1000.0 < period_ms) {
        std::fprintf(stderr, "sb_ros2_cycle: --seconds %g is shorter than a period (%u ms)\n", seconds, period_ms);
        return 2;
    }
    ServoBusHardware hw;
    if (!hw.on_init(host, port, ids, period_ms, sim) || !hw.on_activate())
        return 1; // each has said why
    std::vector<double> start = hw.command();
    const double target = 10.0 / 180.0 * M_PI; // each joint 10 degrees on, in the first half
    const int cycles = static_cast<int>(seconds * 1000.0 / period_ms);
    uint64_t due = hw.now_us();
    for (int c = 0; c < cycles; c++) {
        if (!hw.read())
            return 1;
        double f = std::min(1.0, 2.0 * c / cycles);
        for (size_t k = 0; k < ids.size(); k++)
            hw.command()[k] = hw.within(k, start[k] + target * f);
        if (!hw.write())
            return 1;
        due += period_ms * 1000u;
        while (hw.now_us() < due)
            std::this_thread::sleep_for(std::chrono::microseconds(200));
    }
    hw.read();
    double worst = 0.0;
    for (size_t k = 0; k < ids.size(); k++)
        worst = std::max(worst, std::fabs(hw.position()[k] - hw.command()[k]) * 180.0 / M_PI);
    std::printf("cycles %d joints %zu missed %u worst error %.2f deg\n", cycles, ids.size(), hw.missed(), worst);
    // A state may be missed where a loaded PC stalls the host past a round's
    // time-out; the joints must still end where they were sent.
    if (hw.missed() * 10 > static_cast<unsigned>(cycles * ids.size())) {
        std::fprintf(stderr, "sb_ros2_cycle: %u of %zu states missed: more than one in ten\n", hw.missed(),
                     cycles * ids.size());
        return 1;
    }
    if (worst >= 1.0) {
        std::fprintf(stderr, "sb_ros2_cycle: a joint ended %.2f deg from its command: 1 deg at most\n", worst);
        return 1;
    }
    return 0;
}
