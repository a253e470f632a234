/* tightknot frames: a film's frames at equal flow time from a run's
 * snapshots and log (tools/tightknot_frames.c). */
#ifndef TK_TOOLS_FRAMES_H
#define TK_TOOLS_FRAMES_H

extern const char tk_frames_help[];

/* Runs `tightknot frames ARGS...` (argv after "frames"); returns the exit
 * status (0 ok, 1 usage, 2 bad input). */
int tk_frames_main(int argc, char **argv);

#endif
