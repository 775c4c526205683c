// A ros2_control-style hardware interface over servobus, without ROS: the
// controller manager's cycle is read() (every joint's state), update (here a
// ramp), write() (every joint's command). write() sends the setpoints and the
// next Sync Monitor in one burst; read() takes its answers.
//
//   sb_ros2_cycle HOST:PORT [--clock FILE] [--ids ID,ID,...] [--seconds S] [--period-ms MS]
//   (--ids: default 1; --seconds: 1; --period-ms: 10)
//
// Exit 0 when nine states in ten or more came and each joint ends within 1
// degree of its command (tools/tests/test_servobus_examples.py runs it against servo_sim).
#include <cmath>
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
    char buf[200];
    sb_error_text(&e, buf, sizeof buf);
    return buf;
}

class ServoBusHardware {
  public:
    bool on_init(const std::string &host, unsigned port, const std::vector<uint8_t> &ids, uint16_t period_ms,
                 bool sim_clock)
    {
        if (sb_tcp_open(&link_, host.c_str(), port) != 0) {
            std::fprintf(stderr, "cannot connect to %s:%u\n", host.c_str(), port);
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
        states_.resize(ids.size());
        return check(sb_loop_init(&loop_, &bus_, ids_.data(), ids_.size(), period_ms));
    }

    // Every joint answers; commands start where the joints are.
    bool on_activate()
    {
        for (uint8_t id : ids_) {
            sb_ping_request p = {id};
            sb_ping_answer a;
            if (!check(sb_call_ping(&bus_, &p, &a)))
                return false;
        }
        bool got[SB_MAX_SERVOS];
        if (!check(sb_sync_monitor(&bus_, ids_.data(), ids_.size(), states_.data(), got)))
            return false;
        for (size_t k = 0; k < ids_.size(); k++)
            command_[k] = position_[k] = states_[k].angle / kDeciDegPerRad;
        return true;
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
        sb_error e = sb_stream_frame(&loop_.stream, angles, nullptr, bus_.tx, sizeof bus_.tx - loop_.monitor_len, &len);
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
    std::vector<sb_monitor_answer> states_;
    bool pending_ = false;
    unsigned missed_ = 0;
};

} // namespace

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
    unsigned port = static_cast<unsigned>(std::atoi(where.substr(where.rfind(':') + 1).c_str()));
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
            for (char *tok = std::strtok(&val[0], ","); tok != nullptr; tok = std::strtok(nullptr, ",")) {
                char *end = nullptr;
                long id = std::strtol(tok, &end, 10);
                if (*end != '\0' || id < 0 || id > SB_MAX_ID) { /* 255 is broadcast: no joint answers it */
                    std::fprintf(stderr, "sb_ros2_cycle: --ids: '%s' is not a servo ID (0-%u)\n", tok, SB_MAX_ID);
                    return 2;
                }
                ids.push_back(static_cast<uint8_t>(id));
            }
        } else if (opt == "--seconds") {
            seconds = std::atof(val.c_str());
        } else if (opt == "--period-ms") {
            period_ms = static_cast<uint16_t>(std::atoi(val.c_str()));
        } else {
            return usage(argv[0]);
        }
    }
    if (ids.empty()) {
        return usage(argv[0]);
    }
    ServoBusHardware hw;
    if (!hw.on_init(host, port, ids, period_ms, sim) || !hw.on_activate())
        return 1;
    std::vector<double> start = hw.command();
    const double target = 10.0 / 180.0 * M_PI; // each joint 10 degrees on, in the first half
    const int cycles = static_cast<int>(seconds * 1000.0 / period_ms);
    uint64_t due = hw.now_us();
    for (int c = 0; c < cycles; c++) {
        if (!hw.read())
            return 1;
        double f = std::min(1.0, 2.0 * c / cycles);
        for (size_t k = 0; k < ids.size(); k++)
            hw.command()[k] = start[k] + target * f;
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
    return hw.missed() * 10 <= static_cast<unsigned>(cycles * ids.size()) && worst < 1.0 ? 0 : 1;
}
