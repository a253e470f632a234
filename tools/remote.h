/* tightknot remote: the client of a tightknot service (tools/tightknot_remote.c). */
#ifndef TK_TOOLS_REMOTE_H
#define TK_TOOLS_REMOTE_H

extern const char tk_remote_help[];

/* Runs `tightknot remote ARGS...` (argv after "remote"); returns the exit
 * status (0 ok, 1 usage, 2 a job or the input failed, 3 the server could
 * not be reached or answered with an error). */
int tk_remote_main(int argc, char **argv);

#endif
