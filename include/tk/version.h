/* tightknot: the release, one definition for every program (tightknot
 * --version, tightknotd --version). */
#ifndef TK_VERSION_H
#define TK_VERSION_H

#define TK_VERSION "0.9.0"

#endif
