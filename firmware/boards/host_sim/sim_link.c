#define _GNU_SOURCE
#include "sim_link.h"

#include <arpa/inet.h>
#include <errno.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/uio.h>
#include <termios.h>
#include <time.h>
#include <unistd.h>

int sim_listen_on(int port, int *bound_port)
{
    int fd = socket(AF_INET, SOCK_STREAM | SOCK_NONBLOCK, 0);
    int one = 1;
    setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
    struct sockaddr_in addr = {.sin_family = AF_INET, .sin_port = htons((uint16_t)port)};
    addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    if (fd < 0 || bind(fd, (struct sockaddr *)&addr, sizeof addr) != 0 || listen(fd, 4) != 0) {
        fprintf(stderr, "servo_sim: cannot listen on 127.0.0.1:%d: %s\n", port, strerror(errno));
        exit(1);
    }
    socklen_t len = sizeof addr;
    getsockname(fd, (struct sockaddr *)&addr, &len);
    *bound_port = ntohs(addr.sin_port);
    return fd;
}

/* A pty in raw mode; the slave stays open so the master never sees EIO
 * between clients. */
int sim_open_pty(const char *link, char *name, size_t name_size, int *slave_fd)
{
    int master = posix_openpt(O_RDWR | O_NOCTTY | O_NONBLOCK);
    if (master < 0 || grantpt(master) != 0 || unlockpt(master) != 0) {
        fprintf(stderr, "servo_sim: cannot make a pseudo-terminal: %s\n", strerror(errno));
        exit(1);
    }
    snprintf(name, name_size, "%s", ptsname(master));
    *slave_fd = open(name, O_RDWR | O_NOCTTY);
    struct termios t;
    if (*slave_fd >= 0 && tcgetattr(*slave_fd, &t) == 0) {
        cfmakeraw(&t);
        tcsetattr(*slave_fd, TCSANOW, &t);
    }
    if (link != NULL) {
        unlink(link);
        if (symlink(name, link) != 0) {
            fprintf(stderr, "servo_sim: cannot link %s to %s: %s\n", link, name, strerror(errno));
            exit(1);
        }
    }
    return master;
}

void sim_stamp_arrivals(int fd)
{
    int one = 1;
    setsockopt(fd, SOL_SOCKET, SO_TIMESTAMPNS, &one, sizeof one);
}

ssize_t sim_read_host(int fd, uint8_t *buf, size_t len, uint64_t *ago_us)
{
    struct iovec iov = {.iov_base = buf, .iov_len = len};
    union {
        char space[CMSG_SPACE(sizeof(struct timespec))];
        struct cmsghdr align;
    } control;
    struct msghdr msg = {.msg_iov = &iov, .msg_iovlen = 1, .msg_control = control.space,
                         .msg_controllen = sizeof control.space};
    *ago_us = 0;
    ssize_t n = recvmsg(fd, &msg, 0);
    if (n < 0 && errno == ENOTSOCK) {
        return read(fd, buf, len); /* a pty */
    }
    for (struct cmsghdr *c = n > 0 ? CMSG_FIRSTHDR(&msg) : NULL; c != NULL; c = CMSG_NXTHDR(&msg, c)) {
        if (c->cmsg_level == SOL_SOCKET && c->cmsg_type == SCM_TIMESTAMPNS) {
            struct timespec at, now;
            memcpy(&at, CMSG_DATA(c), sizeof at);
            clock_gettime(CLOCK_REALTIME, &now);
            int64_t ago = ((int64_t)now.tv_sec - at.tv_sec) * 1000000 + (now.tv_nsec - at.tv_nsec) / 1000;
            *ago_us = ago > 0 ? (uint64_t)ago : 0u;
        }
    }
    return n;
}
