/* The host's side of the simulator: a TCP port on 127.0.0.1 (the bus, or
 * the control port) or a pseudo-terminal in raw mode. Each exits with a
 * message when the system refuses. */
#ifndef SIM_LINK_H
#define SIM_LINK_H

#include <stddef.h>
#include <stdint.h>
#include <sys/types.h>

/* A listening socket; *bound_port is the port it got (port 0: any free). */
int sim_listen_on(int port, int *bound_port);
/* A pty's master; its name in name, link (if not NULL) a symlink to it. */
int sim_open_pty(const char *link, char *name, size_t name_size, int *slave_fd);

/* Reads the host's bytes (read(2)'s result); *ago_us: how long ago, in
 * microseconds, the kernel took them in (a socket that stamps them:
 * sim_stamp_arrivals), else 0. */
ssize_t sim_read_host(int fd, uint8_t *buf, size_t len, uint64_t *ago_us);
/* The kernel stamps what the socket receives (SO_TIMESTAMPNS). */
void sim_stamp_arrivals(int fd);

#endif
