/* Links libfgsr_client and calls it: connecting to a socket nobody listens on is
 * DAEMON_UNAVAILABLE, and the status table is reachable. Exit 0 on the expected results. */
#include <fgsr/client.h>

#include <stdio.h>
#include <string.h>

int main(void) {
    fgsr_connect_info info;
    memset(&info, 0, sizeof(info));
    info.struct_size = sizeof(info);
    info.socket_path = "/nonexistent/fgsrd.sock";
    fgsr_connection* c = NULL;
    const fgsr_status s = fgsr_connect(&info, &c);
    printf("fgsr_connect: %s\n", fgsr_status_string(s));
    return s == FGSR_STATUS_DAEMON_UNAVAILABLE && c == NULL ? 0 : 1;
}
