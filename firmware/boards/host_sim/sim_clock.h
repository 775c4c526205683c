/* The bus clock where a host can read it without asking: a file in the
 * state folder, mapped, holding the clock in microseconds (little-endian
 * u64 at offset 0, written whole after every step). A host that reads the
 * clock at every answer spends no simulated time on it, as a host on a
 * real bus reads its own clock; "clock" on the control port stays.
 *
 * At offset 8 the host may write (u64, microseconds) the bus time it is
 * waiting for: until the clock reaches it, the simulator runs as fast as it
 * can instead of following the wall clock (sim_now_us() skips ahead), then
 * follows the wall clock again from there. 0, the file's start, never
 * skips: a host that does not write it has a real-time simulator. With
 * SIM_CLOCK_UNTIL_ANSWER set, the host waits for an answer: the simulator
 * stops running ahead once it has sent the host bytes since the host's
 * last and the wire is quiet. Started with --clock paced, the simulator
 * never follows the wall clock: it stands still once it has reached the
 * time the host waits for (or answered it), so what the host does between
 * its waits takes no simulated time, however long a loaded PC makes it
 * (tests whose host paces an experiment: identify). At offset 16 such a
 * host writes how many bytes it has sent on the bus in all: a paced
 * simulator runs only once it has read them all, so a request is taken
 * when it was sent, however late the PC hands it over. At offset 24 it
 * writes how many bytes it has read off the bus in all: one that waits for
 * an answer having read every byte it was sent waits for more (a Sync
 * Monitor's answers after an absent servo's silent slot), and the
 * simulator runs on to them. Written only once bytes have come since the
 * host last sent: those before are the last answer's, which a simulator
 * held up may not yet have stood still at. */
#ifndef SIM_CLOCK_H
#define SIM_CLOCK_H

#include <stdbool.h>
#include <stdint.h>

#define SIM_CLOCK_FILE "bus.clock"
#define SIM_CLOCK_UNTIL_ANSWER (UINT64_C(1) << 63)

/* Maps state_dir/SIM_CLOCK_FILE; its path in path. False (and the clock
 * only on the control port) where the system refuses. */
bool sim_clock_open(const char *state_dir, char *path, unsigned path_size);
void sim_clock_publish(uint64_t now_us);
/* The bus time the host waits for (offset 8); 0 if none or unmapped. */
uint64_t sim_clock_host_waits(void);
/* The bytes a paced host says it has sent (offset 16); 0 if none. */
uint64_t sim_clock_host_sent(void);
/* The bytes a paced host says it has read (offset 24); 0 if none. */
uint64_t sim_clock_host_received(void);

#endif
