/* tightknot: the command-line program.
 *
 *   tightknot info [--json] [--tolerance EPS] FILE...
 *   tightknot struts [--json] [--tolerance EPS] FILE
 *   tightknot generate torus P Q | figure-eight | lissajous NX NY NZ | hopf | borromean | chain K
 *                      | clasp
 *                      | deform FILE [SEED] | relax FILE [STEPS]
 *                      | turn FILE [SEED] | wander FILE [SEED]
 *                      [--vertices N] [--disguise SEED]
 *   tightknot tighten FILE [run options] [-o OUT] [--struts OUT] [--log OUT]
 *                    [--snapshots DIR --every K] [--json]
 *   tightknot remote [--server URL] submit|status|cancel|fetch ...
 *
 * One static function per subcommand; options are parsed by one shared
 * helper that knows which options each subcommand accepts.  Options may
 * come before or after the other arguments ("generate torus 2 3
 * --vertices 90"), "--" ends them, "-" as a file is standard input.
 *
 * Exit status: 0 success, 1 usage error (the message names the option or
 * argument), 2 bad input (the engine's message, "FILE:LINE: what").
 */
#include <ctype.h>
#include <errno.h>
#include <jansson.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tk/curve.h"
#include "tk/error.h"
#include "tk/generate.h"
#include "tk/relax.h"
#include "tk/version.h"
#include "tk/invariants.h"
#include "tk/record.h"
#include "cli.h"
#include "jsonmap.h"
#include "tk/struts.h"
#include "tk/thickness.h"
#include "tk/tighten.h"
#include "tk/vect.h"

#include "frames.h"
#include "remote.h"

#include <sys/stat.h>
#include <unistd.h>

enum { EXIT_OK = 0, EXIT_USAGE = 1, EXIT_INPUT = 2 };

#define DEFAULT_TOLERANCE 1e-4

/* ------------------------------------------------------------ help texts */

/* The catalogue a bare knot name is looked up in when no file has that
 * name: $TIGHTKNOT_CATALOGUE, else the project's ../shared/catalogue. */
#define CATALOGUE_DEFAULT "../shared/catalogue"

static const char main_help[] =
    "usage: tightknot COMMAND [OPTIONS] [ARGUMENTS]\n"
    "\n"
    "Measures and makes polygonal knots and links in Geomview VECT format.\n"
    "\n"
    "Commands:\n"
    "  info       length, thickness, ropelength, contacts and knot or link type\n"
    "             of VECT files\n"
    "  struts     the struts (self-contacts) and kinks of one VECT file\n"
    "  generate   write a knot or link as VECT on standard output: an example\n"
    "             (torus P Q, figure-eight, lissajous NX NY NZ, hopf,\n"
    "             borromean, chain K, clasp) or a start of another shape with a\n"
    "             file's type (deform FILE, relax FILE, turn FILE, wander FILE)\n"
    "  tighten    tighten a knot or link: shorten it keeping the tube embedded\n"
    "  remote     use a tightknot service: submit files, list, status, cancel,\n"
    "             delete and fetch jobs, a job's film frames\n"
    "  frames     a film's frames at equal flow time from a run's snapshots\n"
    "  help       show the help of a command: tightknot help info\n"
    "\n"
    "A FILE is a path, '-' for standard input, or the name of a knot of the\n"
    "catalogue (tightknot tighten 7.2) when no file has that name: looked up in\n"
    "$TIGHTKNOT_CATALOGUE, else " CATALOGUE_DEFAULT ".\n"
    "\n"
    "Options:\n"
    "  -h, --help   show this help; 'tightknot COMMAND --help' shows a command's\n"
    "  --version    the release\n"
    "\n"
    "Conventions: the thickness is the diameter of the thickest embedded tube\n"
    "(min of 2 * minrad and the shortest doubly critical self-distance);\n"
    "ropelength = length / tube radius = 2 * length / thickness, the convention\n"
    "of the published tables (tight trefoil about 32.74, tight Hopf link 8 pi).\n"
    "\n"
    "Exit status: 0 success, 1 usage error, 2 bad input.\n"
    "\n"
    "Example:\n"
    "  tightknot generate torus 2 3 > trefoil.vect && tightknot info trefoil.vect\n";

static const char info_help[] =
    "usage: tightknot info [--json] [--tolerance EPS] FILE...\n"
    "\n"
    "Measures each VECT file (\"-\" is standard input): its number of\n"
    "components and vertices, length, thickness, minrad, ropelength, how\n"
    "many struts and kinks are active, that is within a relative tolerance of\n"
    "the thickness, and its knot or link type.\n"
    "\n"
    "  thickness   tube diameter: min(2 * minrad, shortest doubly critical\n"
    "              self-distance)\n"
    "  minrad      smallest polygonal radius of curvature,\n"
    "              min(|e_{i-1}|, |e_i|) / (2 tan(theta_i / 2))\n"
    "  ropelength  length / tube radius = 2 * length / thickness\n"
    "  struts      admissible edge pairs at distance <= thickness * (1 + EPS)\n"
    "  kinks       vertices with 2 * minrad <= thickness * (1 + EPS)\n"
    "  type        for a knot its determinant |Delta(-1)| and Alexander\n"
    "              polynomial Delta(t) (normalised so that Delta(1) = 1):\n"
    "              \"det 3, 1 - t + t^2\" is the trefoil; for a link the\n"
    "              determinant of each component, the linking number of\n"
    "              each pair and the whole link's determinant: \"det 1 1,\n"
    "              lk 0-1: 1, link det 2\" is the Hopf link.  \"?\"\n"
    "              for what cannot be told (an open component, a projection\n"
    "              with too many crossings, strands that (nearly) meet)\n"
    "\n"
    "Options:\n"
    "  --json            one JSON object per file and line, with the names\n"
    "                    file, components, vertices, length, thickness, minrad,\n"
    "                    ropelength, struts, kinks (full precision; null for a\n"
    "                    value that is not finite) and invariants:\n"
    "                    {\"alexander\": [[1, -1, 1]] (each component's\n"
    "                    coefficients of 1, t, t^2, ...), \"alexander_text\",\n"
    "                    \"determinants\", \"link_determinant\" (the whole\n"
    "                    link's), \"linking\" (the matrix of linking\n"
    "                    numbers), \"complete\"} (null for what cannot be told)\n"
    "  --tolerance EPS   relative tolerance for struts and kinks, >= 0\n"
    "                    (default 1e-4)\n"
    "  -h, --help        show this help\n"
    "\n"
    "Every file is processed; the exit status is 2 if any could not be read\n"
    "(the message, on standard error, is \"tightknot: FILE:LINE: what\"), 1 on\n"
    "a usage error, 0 otherwise.\n"
    "\n"
    "Example:\n"
    "  tightknot info --json ../shared/catalogue/3.1.vect\n";

static const char struts_help[] =
    "usage: tightknot struts [--json] [--tolerance EPS] FILE\n"
    "\n"
    "Lists the active contacts of one VECT file (\"-\" is standard input):\n"
    "every strut (an admissible pair of edges at distance within\n"
    "thickness * (1 + EPS), a local minimum of the self-distance) and every\n"
    "kink (a vertex where 2 * minrad is within the same bound), with the\n"
    "thickness (tube diameter) they are measured against.\n"
    "\n"
    "A strut gives its two edges as component:edge pairs (edge k of a\n"
    "component runs from its vertex k to vertex k+1, counting from 0), the\n"
    "parameters s and t in [0, 1] of its end points along them, the end\n"
    "points p and q, and its length |p - q|.  A kink gives its component,\n"
    "vertex and minrad.\n"
    "\n"
    "Options:\n"
    "  --json            one JSON object: {\"file\", \"thickness\",\n"
    "                    \"struts\": [{\"edges\": [[c, i], [c, j]], \"s\", \"t\",\n"
    "                    \"p\": [x, y, z], \"q\": [x, y, z], \"length\"}],\n"
    "                    \"kinks\": [{\"comp\", \"vertex\", \"minrad\"}]}\n"
    "  --tolerance EPS   relative tolerance, >= 0 (default 1e-4)\n"
    "  -h, --help        show this help\n"
    "\n"
    "Conventions: thickness = tube diameter; ropelength = length / tube\n"
    "radius = 2 * length / thickness.  Exit status: 0 success, 1 usage\n"
    "error, 2 bad input.\n"
    "\n"
    "Example:\n"
    "  tightknot struts --tolerance 1e-3 ../shared/catalogue/3_1_328.vect\n";

static const char generate_help[] =
    "usage: tightknot generate SHAPE [--vertices N] [--disguise SEED]\n"
    "\n"
    "Writes an example knot or link as VECT (full precision) on standard\n"
    "output.  Every component is a closed polygon with vertices evenly\n"
    "spaced in its parameter.  SHAPE is one of:\n"
    "\n"
    "  torus P Q   the torus knot or link T(P, Q), P, Q >= 1, on the torus of\n"
    "              radii 2 and 1; gcd(P, Q) components (T(2,3) is the\n"
    "              trefoil, T(2,4) a two-component link)\n"
    "  figure-eight  the figure-eight knot ((2 + cos 2t) cos 3t,\n"
    "              (2 + cos 2t) sin 3t, sin 4t)\n"
    "  lissajous NX NY NZ [PX PY PZ]\n"
    "              the Lissajous knot (cos(NX t + PX), cos(NY t + PY),\n"
    "              cos(NZ t + PZ)): frequencies pairwise coprime, 1 to 1000;\n"
    "              phases default 0.7 0.2 0.  3 2 5 is the knot 6_1, 3 2 7\n"
    "              0.7 0.7 0 the knot 5_2; 'tightknot info' shows the type.\n"
    "              Phases that make the curve pass through itself are refused;\n"
    "              at most 10000 vertices\n"
    "  hopf        the Hopf link: two circles of radius 1 in perpendicular\n"
    "              planes, each through the other's centre (tight at\n"
    "              thickness 1: ropelength 8 pi); N is rounded up to even\n"
    "  borromean   the Borromean rings: three perpendicular ellipses with\n"
    "              semi-axes 2 and 1\n"
    "  deform FILE [SEED]\n"
    "              a start of another shape with FILE's type: the largest\n"
    "              smooth random deformation (three Fourier modes along\n"
    "              each component, drawn from SEED, default 1) that keeps\n"
    "              FILE's knot or link type and a twentieth of its\n"
    "              thickness ('-': standard input)\n"
    "  relax FILE [STEPS]\n"
    "              FILE's curve relaxed under a repulsive energy at its own\n"
    "              length (every strand pushed from every other, bends\n"
    "              smoothed out), for at most STEPS steps (default 2000):\n"
    "              a shape of the same type that forgets the file's; its\n"
    "              type is kept exactly (closed components only)\n"
    "  turn FILE [SEED]\n"
    "              FILE's curve turned inside out: inverted in a sphere about\n"
    "              its centroid (SEED 0, the default) or a point near it\n"
    "              (drawn from SEED), mirrored, and relaxed for 3000 steps;\n"
    "              what wound around the centre then winds around the curve\n"
    "              (a torus knot's T(p,q) form becomes its T(q,p) form), the\n"
    "              type kept; --vertices N in all (default FILE's count)\n"
    "  wander FILE [SEED]\n"
    "              FILE's curve drawn toward a far random shape (three Fourier\n"
    "              modes as large as the curve, from SEED, default 1) as far\n"
    "              as its strands let it, then relaxed: every step too short\n"
    "              for an edge to pass through another, so the type is kept\n"
    "              exactly, links of unknots included (closed components)\n"
    "  chain K     K >= 1 rings of radius 1, centres 1.5 apart on the x axis,\n"
    "              in alternating planes, each linked with its neighbours\n"
    "  clasp       two open ropes hooked over each other at right angles,\n"
    "              the ends of one sliding on the plane z = 2.5, of the\n"
    "              other on z = -2.5 (the paper's Table 2 clasp; bench/table2.sh\n"
    "              measures it)\n"
    "\n"
    "Options:\n"
    "  --vertices N   vertices per component (default: torus about 40 per\n"
    "                 turn, at least 60; figure-eight 200; lissajous 60 per\n"
    "                 turn of the fastest angle, at least 12; hopf 64;\n"
    "                 borromean 96; chain 64; clasp 64 a rope).\n"
    "                 Too few to keep the polygon embedded is refused.\n"
    "  --disguise SEED   the same knot or link as another start would give\n"
    "                 it: vertices moved along each component to uneven\n"
    "                 spacing, displaced at random by 5% of the mean edge,\n"
    "                 and the whole turned by a random rotation, all drawn\n"
    "                 from SEED (an integer; the same seed, the same curve)\n"
    "  -h, --help     show this help\n"
    "\n"
    "Conventions (as in 'tightknot info'): thickness is the tube diameter,\n"
    "ropelength = length / tube radius = 2 * length / thickness; so the\n"
    "generated Hopf link has thickness near 1 and ropelength near 8 pi.\n"
    "\n"
    "Exit status: 0 success, 1 usage error (including a shape argument out\n"
    "of range), 2 failure writing the output.\n"
    "\n"
    "Example:\n"
    "  tightknot generate torus 2 3 --vertices 150 > trefoil.vect\n"
    "  tightknot generate figure-eight --disguise 7 > figure-eight.vect\n"
    "  tightknot generate lissajous 3 2 5 > 6_1.vect\n";

static const char tighten_help[] =
    "usage: tightknot tighten FILE [OPTIONS]\n"
    "\n"
    "Tightens the knot or link in FILE (\"-\" is standard input) by the\n"
    "constrained gradient flow: the curve gets shorter while the tube of\n"
    "the given radius around it stays embedded (struts and kinks are the\n"
    "active constraints, resolved by non-negative least squares).\n"
    "\n"
    "Run options (the service's job options, by the same names):\n";

static const char tighten_help_end[] =
    "\n"
    "A run stops at the first of its stop criteria met.\n"
    "\n"
    "Defaults that tighten: with neither --steps nor --residual (the stops\n"
    "that end the flow at a chosen point, to compare runs) a run goes coarse\n"
    "to fine at --resolution 5 (unless a resolution or --vertices is given),\n"
    "autoscales and tries its escapes; given no --time or --work either, it\n"
    "stops when it has converged as far as its tolerances allow, or after 120\n"
    "of work (--work 120: about 120 s of a processor, and the same run on any\n"
    "machine at any load): 'tightknot tighten 4.1' ends at the tight\n"
    "figure-eight.  A --time or --work is run out (add --converge to stop\n"
    "sooner when converged).  With --steps or --residual every option is as\n"
    "given.\n"
    "\n"
    "Constraints on vertices (the file's own, '# Constraint K Plane a b c\n"
    "d' in its header and '# Cst: K' after a vertex, come first):\n"
    "  --constrain COMP:VERTEX=KIND   repeatable; the vertex (counted from 0\n"
    "                          in its component) stays fixed (where it is),\n"
    "                          at point:x,y,z, on plane:nx,ny,nz,d (n.x = d)\n"
    "                          or on line:px,py,pz,tx,ty,tz, or is free (an\n"
    "                          open component's ends are fixed unless\n"
    "                          constrained otherwise); e.g. the ends of an\n"
    "                          open rope sliding on two planes:\n"
    "                          --constrain 0:0=plane:0,0,1,-10\n"
    "                          --constrain 0:99=plane:0,0,1,10\n"
    "\n"
    "Outputs:\n"
    "  -o, --output OUT.vect   the tightened curve (VECT, with its\n"
    "                          constraints)\n"
    "  --struts OUT.json       the final struts and kinks with their forces\n"
    "                          ('-' for either: standard output, and the\n"
    "                          report then goes to standard error)\n"
    "  --log OUT.tsv           one line of figures per step\n"
    "  --snapshots DIR         write DIR/step-NNNNNN.vect every K steps\n"
    "  --every K               snapshot interval (default 100)\n"
    "  --json                  print one JSON object: the file, the last\n"
    "                          step's figures (the columns of --log: step,\n"
    "                          seconds, ropelength, length, thickness, minrad,\n"
    "                          residual, struts, kinks, ...), components,\n"
    "                          steps, stop_reason, options (the run options as\n"
    "                          used), invariants: {start, result}, the knot or\n"
    "                          link type of the input and of the result, as in\n"
    "                          'tightknot info --json', escapes: [{step,\n"
    "                          from, amplitude, coarse, reached, improved,\n"
    "                          explored, turned}], one per escape tried\n"
    "                          (explored: on the coarsest polygon alone,\n"
    "                          before the first refinement; turned: the curve\n"
    "                          turned inside out, as 'generate turn', not\n"
    "                          deformed), basins: {basins: [{ropelength,\n"
    "                          times}], best_reached, note}, the distinct\n"
    "                          results its tightenings on the final polygon\n"
    "                          reached, lowest first, with how often (a\n"
    "                          lowest reached once is noted: run longer or\n"
    "                          with more seeds), and recovery: {undone_steps,\n"
    "                          rescales, largest_rescale, bent_corrections,\n"
    "                          length_steps, corrected_steps}, error\n"
    "                          recovery's last resorts and the steps judged\n"
    "                          by their length alone or after their correction\n"
    "  -h, --help              show this help\n"
    "\n"
    "A progress line (with the share of the budget spent and the time left)\n"
    "goes to standard error when it is a terminal; --progress prints it\n"
    "there every 5 s when it is not.  The\n"
    "conventions are those of 'tightknot info': thickness is the tube\n"
    "diameter, ropelength = 2 * length / thickness.\n"
    "\n"
    "The knot or link type (see 'tightknot help info') is checked after every\n"
    "resampling and at the end: a run whose type changed (a strand passed\n"
    "through another) fails, saying which polynomial or linking number\n"
    "changed.\n"
    "\n"
    "Exit status: 0 success, 1 usage error, 2 bad input or a failed run.\n"
    "\n"
    "Example:\n"
    "  tightknot tighten ../shared/catalogue/3.1.vect --autoscale --resolution 5 \\\n"
    "      --time 60 -o trefoil-tight.vect --json\n";

/* -------------------------------------------------------- option parsing */

/* The subcommands, as bits: which take which option. */
enum { CMD_INFO = 1u, CMD_STRUTS = 2u, CMD_GENERATE = 4u, CMD_TIGHTEN = 8u };

typedef struct cli_args {
    bool help;
    bool json;
    bool progress;        /* tighten: plain progress lines on stderr */
    double tolerance;
    size_t vertices;      /* 0: the generator's default */
    const char *disguise; /* generate: tk_generate_disguise with seed */
    unsigned long long seed;
    tk_options run;       /* tighten's run options */
    tk_options_given given; /* those on the line */
    const char *output, *struts_out, *log_out, *snapshots;
    const char *constrain[TK_PIN_MOST]; /* tighten: --constrain, in order */
    size_t nconstrain;
    size_t every;
    int npos;             /* the arguments that are not options, in order */
    char **pos;
} cli_args;

/* The command line's own numbers; tighten also takes every named run
 * option (tk/record.h). */
#define OWN(fld, kind, dflt, lo, hi, nm) TK_FIELD_ROW(cli_args, fld, fld, kind, dflt, lo, hi, nm, "")
static const tk_field own_fields[] = {
    OWN(tolerance, REAL, DEFAULT_TOLERANCE, 0, INFINITY, "tolerance"),
    OWN(vertices, SIZE, 0, 0, 0x1p53, "vertices"), /* 0: the generator's default */
    OWN(every, SIZE, 100, 1, 0x1p53, "every"),
    OWN(seed, SEED, 0, 0, 0x1p53, "disguise"),
};
enum { OWN_TOLERANCE, OWN_VERTICES, OWN_EVERY, OWN_SEED };

/* Prints "tightknot CMD: message" and a pointer to the help on stderr;
 * returns EXIT_USAGE. */
static int usage_error(const char *cmd, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;

static int usage_error(const char *cmd, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    fprintf(stderr, "tightknot%s%s: ", cmd ? " " : "", cmd ? cmd : "");
    vfprintf(stderr, fmt, ap);
    va_end(ap);
    fprintf(stderr, "\nTry 'tightknot%s%s --help'.\n", cmd ? " " : "", cmd ? cmd : "");
    return EXIT_USAGE;
}

static int parse_integer(const char *cmd, const char *what, const char *text,
                         long long lo, long long hi, long long *out)
{
    char *end = NULL;
    errno = 0;
    long long x = strtoll(text, &end, 10);
    if (end == text || *end != '\0' || errno == ERANGE || x < lo || x > hi)
        return usage_error(cmd, "%s: '%s' is not an integer from %lld to %lld", what,
                           text, lo, hi);
    *out = x;
    return EXIT_OK;
}

static int parse_real(const char *cmd, const char *what, const char *text, double *out)
{
    char *end = NULL;
    errno = 0;
    double x = strtod(text, &end);
    if (end == text || *end != '\0' || errno == ERANGE || !isfinite(x))
        return usage_error(cmd, "%s: '%s' is not a finite number", what, text);
    *out = x;
    return EXIT_OK;
}

/* Parses argv[0..argc) of a subcommand (argv[0] is the first argument
 * after its name), accepting the options of `cmd` (one CMD_ bit).  The
 * other arguments are gathered, in order, at a->pos.  The help texts
 * above describe these options; tighten's run options are listed from
 * their table. */
static int parse_args(const char *name, int argc, char **argv, unsigned cmd, cli_args *a)
{
    *a = (cli_args){.run = TK_OPTIONS_INIT};
    tk_cli_defaults(own_fields, sizeof own_fields / sizeof own_fields[0], a);
    tk_cli c = {.n = 0};
    tk_cli_flag(&c, "help", 'h', &a->help, NULL);
    if (cmd != CMD_GENERATE)
        tk_cli_flag(&c, "json", 0, &a->json, NULL);
    if (cmd & (CMD_INFO | CMD_STRUTS))
        tk_cli_fields(&c, &own_fields[OWN_TOLERANCE], 1, a);
    if (cmd & CMD_GENERATE) {
        tk_cli_fields(&c, &own_fields[OWN_VERTICES], 1, a);
        tk_cli_text(&c, "disguise", 0, "SEED", &a->disguise, NULL);
    }
    if (cmd & CMD_TIGHTEN) {
        tk_cli_text(&c, "output", 'o', "OUT", &a->output, NULL);
        tk_cli_text(&c, "struts", 0, "OUT", &a->struts_out, NULL);
        tk_cli_text(&c, "log", 0, "OUT", &a->log_out, NULL);
        tk_cli_text(&c, "snapshots", 0, "DIR", &a->snapshots, NULL);
        tk_cli_flag(&c, "progress", 0, &a->progress, NULL);
        tk_cli_texts(&c, "constrain", "C", a->constrain, TK_PIN_MOST, &a->nconstrain,
                     NULL);
        tk_cli_fields(&c, &own_fields[OWN_EVERY], 1, a);
        tk_cli_fields(&c, tk_option_fields, tk_option_nfields, &a->run);
    }
    tk_error err;
    if (tk_cli_parse(&c, argc, argv, &a->npos, &err))
        return usage_error(name, "%s", err.message);
    for (size_t i = 0; i < tk_option_nfields; i++)
        if (tk_option_fields[i].name && tk_cli_given(&c, &a->run, tk_option_fields[i].name))
            tk_options_given_mark(&a->given, tk_option_fields[i].name);
    if (a->disguise && tk_field_parse(&own_fields[OWN_SEED], a, a->disguise, &err))
        return usage_error(name, "--disguise: '%s' is not an integer from 0 to 2^53", a->disguise);
    a->pos = argv;
    return EXIT_OK;
}

/* The named run options, as tighten's --help lists them. */
static void print_run_options(FILE *out)
{
    tk_options run = TK_OPTIONS_INIT;
    tk_cli c = {.n = 0};
    tk_cli_fields(&c, tk_option_fields, tk_option_nfields, &run);
    tk_cli_help(&c, out);
}

/* ---------------------------------------------------------------- output */

/* The path the engine reads for a command-line file name. */
/* The file to read for a FILE argument, into buf: "-" (tk_vect_read_file
 * reads standard input) or an existing file as given; else a name without
 * a slash ("7.2" or "7.2.vect") found in the catalogue; else as given,
 * for the read to fail naming it. */
static const char *input_path(const char *name, char buf[PATH_MAX])
{
    struct stat st;
    if (!strcmp(name, "-") || !stat(name, &st) || strchr(name, '/'))
        return name;
    const char *env = getenv("TIGHTKNOT_CATALOGUE");
    const char *dirs[2] = {env && *env ? env : NULL, CATALOGUE_DEFAULT};
    size_t len = strlen(name);
    bool has_ext = len > 5 && !strcmp(name + len - 5, ".vect");
    for (int d = 0; d < 2; d++) {
        if (!dirs[d])
            continue;
        int n = snprintf(buf, PATH_MAX, "%s/%s%s", dirs[d], name, has_ext ? "" : ".vect");
        if (n > 0 && n < PATH_MAX && !stat(buf, &st) && S_ISREG(st.st_mode))
            return buf;
    }
    return name;
}

/* Whether two paths name one file: the same file when both exist (links
 * and all), else the same name in the same directory. */
static bool same_file(const char *x, const char *y)
{
    struct stat sx, sy;
    if (!stat(x, &sx) && !stat(y, &sy))
        return sx.st_dev == sy.st_dev && sx.st_ino == sy.st_ino;
    char *path[2] = {NULL, NULL};
    const char *given[2] = {x, y};
    for (int k = 0; k < 2; k++) {
        const char *slash = strrchr(given[k], '/');
        char *dir = slash ? strndup(given[k], (size_t)(slash - given[k]) + 1) : strdup(".");
        char *real = dir ? realpath(dir, NULL) : NULL;
        const char *base = slash ? slash + 1 : given[k];
        size_t n = real ? strlen(real) + strlen(base) + 2 : 0;
        if (n && (path[k] = malloc(n)) != NULL)
            snprintf(path[k], n, "%s/%s", real, base);
        free(real);
        free(dir);
    }
    bool same = path[0] && path[1] ? !strcmp(path[0], path[1]) : !strcmp(x, y);
    free(path[0]);
    free(path[1]);
    return same;
}

/* A run's outputs each a file of its own, and none but -o the input
 * (written at the end, -o IN tightens the file in place; --log and
 * --struts would overwrite the knot before it is read back), and not
 * even -o when keep_input (a catalogue's file found by a bare name):
 * refused before any work, as a usage error. */
static int check_outputs(const char *input, bool keep_input, const char *const out[3])
{
    static const char *const flag[3] = {"-o", "--struts", "--log"};
    for (int i = 0; i < 3; i++) {
        if (!out[i])
            continue;
        if (i == 2 && !strcmp(out[i], "-"))
            return usage_error("tighten", "--log - : the log is written while the run goes and "
                               "cannot share standard output with its report; name a file");
        for (int j = 0; j < i; j++)
            if (out[j] && (!strcmp(out[i], "-") || !strcmp(out[j], "-")
                               ? !strcmp(out[i], out[j])
                               : same_file(out[i], out[j])))
                return usage_error("tighten", "%s and %s name one file (%s): each output needs "
                                   "its own", flag[j], flag[i], out[i]);
        if ((i > 0 || keep_input) && strcmp(input, "-") && same_file(out[i], input))
            return usage_error("tighten", "%s names the input %s: it would be lost", flag[i],
                               input);
    }
    return EXIT_OK;
}

/* Prints a JSON value on one line, numbers with 17 significant digits so
 * that they read back as the same doubles.  Takes the reference. */
static int print_json(json_t *value)
{
    char *text = value ? json_dumps(value, JSON_COMPACT | JSON_PRESERVE_ORDER |
                                               JSON_REAL_PRECISION(17))
                       : NULL;
    json_decref(value);
    if (!text) {
        fprintf(stderr, "tightknot: out of memory making JSON\n");
        return EXIT_INPUT;
    }
    puts(text);
    free(text);
    return EXIT_OK;
}

/* Prints an engine failure: the message names the file (and the line,
 * for parse errors) when it comes from the reader; otherwise prefix it. */
static void report(const char *file, const tk_error *err)
{
    if (file)
        fprintf(stderr, "tightknot: %s: %s\n", file, err->message);
    else
        fprintf(stderr, "tightknot: %s\n", err->message);
}

/* Reads and measures one file, with its contacts.  On failure the message
 * is printed and EXIT_INPUT returned. */
static int load_and_measure(const char *name, double tolerance, tk_curve **curve,
                            tk_measure *m, tk_strut_list *struts, tk_kink **kinks,
                            size_t *nkinks)
{
    tk_error err;
    tk_error_clear(&err);
    *kinks = NULL;
    *nkinks = 0;
    char path[PATH_MAX];
    if (tk_vect_read_file(input_path(name, path), NULL, curve, &err) != TK_OK) {
        report(NULL, &err);
        return EXIT_INPUT;
    }
    if (tk_thickness_contacts(*curve, tolerance, m, struts, kinks, nkinks, &err) != TK_OK) {
        report(name, &err);
        tk_curve_free(curve);
        return EXIT_INPUT;
    }
    return EXIT_OK;
}

/* ------------------------------------------------------------- commands */

static void print_info_header(int width)
{
    printf("%-*s %5s %9s %15s %15s %15s %15s %7s %6s  %s\n", width, "file", "comps",
           "vertices", "length", "thickness", "minrad", "ropelength", "struts", "kinks",
           "type");
}

/* The type of c in a few words: "det 3, 1 - t + t^2" for a knot, "det 1 1,
 * lk 0-1: 1, link det 2" for a link (each component's determinant, each
 * pair's linking number, the whole link's determinant); "?" for what is
 * not known (inv NULL: nothing is). */
static void print_type(FILE *f, const tk_curve *c, const tk_invariants *inv)
{
    if (!inv || inv->ncomp != c->ncomp) {
        fputc('?', f);
        return;
    }
    size_t n = inv->ncomp;
    fputs("det", f);
    for (size_t a = 0; a < n; a++)
        if (inv->knot[a].known)
            fprintf(f, " %lld", inv->knot[a].determinant);
        else
            fputs(" ?", f);
    if (n == 1) {
        if (inv->knot[0].known) {
            char poly[1024];
            tk_alexander_format(&inv->knot[0], poly, sizeof poly);
            fprintf(f, ", %s", poly);
        }
        return;
    }
    fputs(", lk", f);
    for (size_t a = 0; a < n; a++)
        for (size_t b = a + 1; b < n; b++) {
            fprintf(f, "%s %zu-%zu: ", a == 0 && b == 1 ? "" : ",", a, b);
            /* an open component links nothing */
            if (c->closed[a] && c->closed[b])
                fprintf(f, "%ld", inv->linking[a * n + b]);
            else
                fputc('?', f);
        }
    if (inv->link_known)
        fprintf(f, ", link det %lld", inv->link_determinant);
    else
        fputs(", link det ?", f);
}

/* Measures one file and prints its line; the table's header goes out
 * with the first line, so that a run where every file fails prints none. */
static int info_one(const char *name, const cli_args *a, int width, bool *header_done)
{
    tk_curve *c = NULL;
    tk_measure m;
    tk_strut_list struts = {NULL, 0, 0};
    tk_kink *kinks = NULL;
    size_t nkinks = 0;
    int status = load_and_measure(name, a->tolerance, &c, &m, &struts, &kinks, &nkinks);
    if (status)
        return status;
    /* A curve whose strands (nearly) meet has no type: shown as unknown,
     * while its figures still are what they are. */
    tk_invariants inv = TK_INVARIANTS_INIT;
    tk_error err;
    bool typed = tk_invariants_compute(c, &inv, &err) == TK_OK;
    if (a->json) {
        json_t *o = json_object();
        json_object_set_new(o, "file", tk_json_text(name));
        json_object_set_new(o, "components", json_integer((json_int_t)c->ncomp));
        json_object_set_new(o, "vertices", json_integer((json_int_t)c->nvert));
        json_object_set_new(o, "length", tk_json_number(m.length));
        json_object_set_new(o, "thickness", tk_json_number(m.thickness));
        json_object_set_new(o, "minrad", tk_json_number(m.minrad));
        json_object_set_new(o, "ropelength", tk_json_number(m.ropelength));
        json_object_set_new(o, "struts", json_integer((json_int_t)struts.count));
        json_object_set_new(o, "kinks", json_integer((json_int_t)nkinks));
        json_object_set_new(o, "invariants", tk_json_invariants(typed ? &inv : NULL));
        if (c->npins) { /* as --constrain writes them */
            json_t *list = json_array();
            for (size_t i = 0; i < c->npins; i++) {
                char text[512];
                tk_pin_format(&c->pins[i], text, sizeof text);
                json_array_append_new(list, json_string(text));
            }
            json_object_set_new(o, "constraints", list);
        }
        status = print_json(o);
    } else {
        if (!*header_done)
            print_info_header(width);
        *header_done = true;
        printf("%-*s %5zu %9zu %15.9g %15.9g %15.9g %15.9g %7zu %6zu  ", width, name,
               c->ncomp, c->nvert, m.length, m.thickness, m.minrad, m.ropelength,
               struts.count, nkinks);
        print_type(stdout, c, typed ? &inv : NULL);
        if (c->npins)
            printf(", %zu constrained vert%s", c->npins, c->npins == 1 ? "ex" : "ices");
        putchar('\n');
    }
    tk_invariants_free(&inv);
    tk_strut_list_free(&struts);
    free(kinks);
    tk_curve_free(&c);
    return status;
}

static int cmd_info(int argc, char **argv)
{
    cli_args a;
    if (parse_args("info", argc, argv, CMD_INFO, &a))
        return EXIT_USAGE;
    if (a.help) {
        fputs(info_help, stdout);
        return EXIT_OK;
    }
    if (a.npos == 0)
        return usage_error("info", "no FILE given");
    int width = 4;
    for (int i = 0; i < a.npos; i++) {
        size_t len = strlen(a.pos[i]);
        if (len > (size_t)width)
            width = len > 60 ? 60 : (int)len;
    }
    int status = EXIT_OK;
    bool header_done = false;
    for (int i = 0; i < a.npos; i++) {
        int one = info_one(a.pos[i], &a, width, &header_done);
        if (one > status)
            status = one;
        /* Results show up as they come, in order with the messages. */
        fflush(stdout);
    }
    return status;
}

static void print_struts_text(const char *name, const tk_measure *m, const tk_strut_list *s,
                              const tk_kink *kinks, size_t nkinks, double tolerance)
{
    printf("file        %s\n", name);
    printf("thickness   %.17g\n", m->thickness);
    printf("length      %.17g\n", m->length);
    printf("ropelength  %.17g\n", m->ropelength);
    printf("bound       %.17g (thickness * (1 + %g))\n", m->thickness * (1.0 + tolerance),
           tolerance);
    printf("\n%zu strut%s\n", s->count, s->count == 1 ? "" : "s");
    if (s->count > 0)
        printf("%6s %12s %12s %10s %10s %36s %36s %12s\n", "#", "edge", "edge", "s", "t",
               "p", "q", "length");
    for (size_t i = 0; i < s->count; i++) {
        const tk_strut *st = &s->items[i];
        char e0[32], e1[32];
        snprintf(e0, sizeof e0, "%zu:%zu", st->comp[0], st->edge[0]);
        snprintf(e1, sizeof e1, "%zu:%zu", st->comp[1], st->edge[1]);
        printf("%6zu %12s %12s %10.6f %10.6f (%10.6f %10.6f %10.6f) (%10.6f %10.6f %10.6f) "
               "%12.9f\n",
               i, e0, e1, st->s, st->t, st->p[0], st->p[1], st->p[2], st->q[0], st->q[1],
               st->q[2], st->length);
    }
    printf("\n%zu kink%s\n", nkinks, nkinks == 1 ? "" : "s");
    if (nkinks > 0)
        printf("%6s %6s %8s %12s\n", "#", "comp", "vertex", "minrad");
    for (size_t i = 0; i < nkinks; i++)
        printf("%6zu %6zu %8zu %12.9f\n", i, kinks[i].comp, kinks[i].vertex, kinks[i].minrad);
}

/* The contacts document of `tightknot struts` and `tighten --struts`: the
 * service's strut list (tk_json_contacts) with the file and thickness. */
static json_t *struts_json(const char *name, const tk_curve *c, double thickness,
                           const tk_strut *struts, size_t nstruts, const tk_kink *kinks,
                           size_t nkinks, bool with_force, const double *pin_force)
{
    json_t *o = json_object();
    json_t *contacts =
        tk_json_contacts(c, struts, nstruts, kinks, nkinks, with_force, pin_force);
    if (!o || !contacts) {
        json_decref(o);
        json_decref(contacts);
        return NULL;
    }
    json_object_set_new(o, "file", tk_json_text(name));
    json_object_set_new(o, "thickness", tk_json_number(thickness));
    json_object_update(o, contacts);
    json_decref(contacts);
    return o;
}

static int cmd_struts(int argc, char **argv)
{
    cli_args a;
    if (parse_args("struts", argc, argv, CMD_STRUTS, &a))
        return EXIT_USAGE;
    if (a.help) {
        fputs(struts_help, stdout);
        return EXIT_OK;
    }
    if (a.npos != 1)
        return usage_error("struts", a.npos == 0 ? "no FILE given" : "one FILE only");
    const char *name = a.pos[0];
    tk_curve *c = NULL;
    tk_measure m;
    tk_strut_list struts = {NULL, 0, 0};
    tk_kink *kinks = NULL;
    size_t nkinks = 0;
    int status = load_and_measure(name, a.tolerance, &c, &m, &struts, &kinks, &nkinks);
    if (status)
        return status;
    if (a.json)
        status = print_json(struts_json(name, c, m.thickness, struts.items, struts.count, kinks,
                                        nkinks, false, NULL));
    else
        print_struts_text(name, &m, &struts, kinks, nkinks, a.tolerance);
    tk_strut_list_free(&struts);
    free(kinks);
    tk_curve_free(&c);
    return status;
}

/* generate deform: the thickness a far deformation keeps, as the escapes'
 * far tries do (engine/escape.c): loose enough that its tightening can
 * find another basin than the file's. */
#define DEFORM_KEEP 0.05
/* generate turn: relaxation steps after the turn, as the escapes'
 * turned tries take (engine/escape.c) */
#define TURN_STEPS 3000
/* generate wander: steps of the pull, and as many of relaxing */
#define WANDER_STEPS 2000

/* The shapes made from a FILE's curve, each with its optional number
 * (a seed, or steps) and the call that makes it. */
static int make_deform(const tk_curve *src, long long seed, size_t vertices, tk_curve **out,
                       tk_error *err)
{
    (void)vertices;
    return tk_generate_deform(src, (unsigned long long)seed, DEFORM_KEEP, out, err);
}

static int make_relax(const tk_curve *src, long long steps, size_t vertices, tk_curve **out,
                      tk_error *err)
{
    (void)vertices;
    return tk_relax(src, NULL, 0.0, (int)steps, out, NULL, err);
}

static int make_wander(const tk_curve *src, long long seed, size_t vertices, tk_curve **out,
                       tk_error *err)
{
    (void)vertices;
    return tk_relax_wander(src, (uint64_t)seed, WANDER_STEPS, out, err);
}

static int make_turn(const tk_curve *src, long long seed, size_t vertices, tk_curve **out,
                     tk_error *err)
{
    double offset[3] = {0.0, 0.0, 0.0};
    uint64_t state = (uint64_t)seed;
    if (seed > 0)
        tk_relax_turn_offset(&state, offset);
    return tk_relax_turn(src, offset, vertices ? vertices : src->nvert, TURN_STEPS, out, err);
}

typedef struct from_file_shape {
    const char *name, *arg;
    long long dflt, lo, hi;
    int (*make)(const tk_curve *src, long long n, size_t vertices, tk_curve **out,
                tk_error *err);
} from_file_shape;

static const from_file_shape from_file_shapes[] = {
    {"deform", "SEED", 1, 0, 1LL << 53, make_deform},
    {"relax", "STEPS", 2000, 1, INT_MAX, make_relax},
    {"turn", "SEED", 0, 0, 1LL << 53, make_turn},
    {"wander", "SEED", 1, 0, 1LL << 53, make_wander},
};

static const from_file_shape *from_file(const char *shape)
{
    for (size_t i = 0; i < sizeof from_file_shapes / sizeof from_file_shapes[0]; i++)
        if (!strcmp(shape, from_file_shapes[i].name))
            return &from_file_shapes[i];
    return NULL;
}

/* Builds the curve a generate command line asks for; EXIT_USAGE with a
 * message when the shape or its arguments are wrong. */
static int make_shape(int npos, char **pos, size_t vertices, tk_curve **out)
{
    const char *cmd = "generate";
    if (npos == 0)
        return usage_error(cmd, "no SHAPE given (torus P Q, figure-eight, lissajous NX NY NZ, "
                                "hopf, borromean, chain K, clasp, deform FILE, relax FILE, turn FILE or wander FILE)");
    const char *shape = pos[0];
    tk_error err;
    tk_error_clear(&err);
    int rc;
    if (strcmp(shape, "torus") == 0) {
        if (npos != 3)
            return usage_error(cmd, "torus takes two arguments, P and Q");
        long long p = 0, q = 0;
        if (parse_integer(cmd, "torus P", pos[1], INT_MIN, INT_MAX, &p) ||
            parse_integer(cmd, "torus Q", pos[2], INT_MIN, INT_MAX, &q))
            return EXIT_USAGE;
        rc = tk_generate_torus((int)p, (int)q, vertices, out, &err);
    } else if (strcmp(shape, "hopf") == 0 || strcmp(shape, "borromean") == 0 ||
               strcmp(shape, "figure-eight") == 0 || strcmp(shape, "clasp") == 0) {
        if (npos != 1)
            return usage_error(cmd, "%s takes no arguments", shape);
        rc = shape[0] == 'h'   ? tk_generate_hopf(vertices, out, &err)
             : shape[0] == 'b' ? tk_generate_borromean(vertices, out, &err)
             : shape[0] == 'c' ? tk_generate_clasp(vertices, out, &err)
                               : tk_generate_figure_eight(vertices, out, &err);
    } else if (strcmp(shape, "lissajous") == 0) {
        if (npos != 4 && npos != 7)
            return usage_error(cmd, "lissajous takes three frequencies NX NY NZ and "
                                    "optionally three phases PX PY PZ");
        static const char *names[] = {"lissajous NX", "lissajous NY", "lissajous NZ",
                                      "lissajous PX", "lissajous PY", "lissajous PZ"};
        int freq[3];
        double phase[3] = {0.7, 0.2, 0.0};
        for (int k = 0; k < 3; k++) {
            long long f = 0;
            if (parse_integer(cmd, names[k], pos[1 + k], 1, 1000, &f) ||
                (npos == 7 && parse_real(cmd, names[3 + k], pos[4 + k], &phase[k])))
                return EXIT_USAGE;
            freq[k] = (int)f;
        }
        rc = tk_generate_lissajous(freq, phase, vertices, out, &err);
    } else if (from_file(shape)) {
        const from_file_shape *f = from_file(shape);
        if (npos != 2 && npos != 3)
            return usage_error(cmd, "%s takes a FILE and optionally %s", shape, f->arg);
        long long n = f->dflt;
        char what[32];
        snprintf(what, sizeof what, "%s %s", shape, f->arg);
        if (npos == 3 && parse_integer(cmd, what, pos[2], f->lo, f->hi, &n))
            return EXIT_USAGE;
        tk_curve *src = NULL;
        char path[PATH_MAX];
        rc = tk_vect_read_file(input_path(pos[1], path), NULL, &src, &err);
        if (!rc)
            rc = f->make(src, n, vertices, out, &err);
        tk_curve_free(&src);
        if (rc == TK_EPARSE || rc == TK_EIO) {
            report(NULL, &err);
            return EXIT_INPUT;
        }
    } else if (strcmp(shape, "chain") == 0) {
        if (npos != 2)
            return usage_error(cmd, "chain takes one argument, K");
        long long k = 0;
        if (parse_integer(cmd, "chain K", pos[1], 1, INT_MAX, &k))
            return EXIT_USAGE;
        rc = tk_generate_chain((size_t)k, vertices, out, &err);
    } else {
        return usage_error(cmd,
                           "unknown shape '%s' (torus P Q, figure-eight, lissajous NX NY NZ, "
                           "hopf, borromean, chain K, clasp, deform FILE, relax FILE, turn FILE or wander FILE)",
                           shape);
    }
    if (rc == TK_EINVAL || rc == TK_ELIMIT)
        return usage_error(cmd, "%s", err.message);
    if (rc) {
        report(NULL, &err);
        return EXIT_INPUT;
    }
    return EXIT_OK;
}

static int cmd_generate(int argc, char **argv)
{
    cli_args a;
    if (parse_args("generate", argc, argv, CMD_GENERATE, &a))
        return EXIT_USAGE;
    if (a.help) {
        fputs(generate_help, stdout);
        return EXIT_OK;
    }
    tk_curve *c = NULL;
    int status = make_shape(a.npos, a.pos, a.vertices, &c);
    if (status)
        return status;
    tk_error err;
    tk_error_clear(&err);
    if (a.disguise) {
        tk_curve *plain = c;
        c = NULL;
        int rc = tk_generate_disguise(plain, a.seed, 0.05, &c, &err);
        tk_curve_free(&plain);
        if (rc) {
            report(NULL, &err);
            return EXIT_INPUT;
        }
    }
    if (tk_vect_write(c, stdout, &err) != TK_OK) {
        report(NULL, &err);
        status = EXIT_INPUT;
    }
    tk_curve_free(&c);
    return status;
}

/* What the tighten command's progress callback needs. */
typedef struct tighten_watch {
    bool terminal;       /* a progress line on stderr, rewritten in place */
    bool plain;          /* --progress: a progress line on stderr every PLAIN_EVERY s */
    double last_print;   /* seconds of the last progress line */
    FILE *log;
    const char *snapshots;
    size_t every;
    tk_run *run;
    const tk_options *opt;
    int failed;          /* an output could not be written */
} tighten_watch;

#define PLAIN_EVERY 5.0

/* The share of the budget spent and the time left, when the run has a
 * budget: "37% of the budget, 76 s left"; a time budget bounds what is
 * left (a run that converges stops sooner), steps and work are reckoned
 * at the pace so far. */
static void budget_text(const tk_options *o, const tk_step_report *s, char *buf, size_t n)
{
    double f = tk_options_spent(o, s);
    buf[0] = '\0';
    if (f < 0.0)
        return;
    double left = INFINITY;
    if (o->max_seconds > 0.0)
        left = o->max_seconds - s->seconds;
    if (o->max_steps > 0 && s->step > 0)
        left = fmin(left, s->seconds * (double)(o->max_steps - s->step) / (double)s->step);
    if (o->max_work > 0.0 && s->work > 0.0)
        left = fmin(left, s->seconds * (o->max_work - s->work) / s->work);
    int len = snprintf(buf, n, "  %3.0f%% of the budget", 100.0 * fmin(f, 1.0));
    if (isfinite(left) && len > 0 && (size_t)len < n)
        snprintf(buf + len, n - (size_t)len, ", %s%.0f s left",
                 o->converge ? "at most " : "", fmax(left, 0.0));
}

/* How a run with these options stops, in words: "when converged or after
 * 120 s of work", the options' stop criteria in the order they are judged. */
static void stops_text(const tk_options *o, char *buf, size_t n)
{
    size_t len = 0;
    buf[0] = '\0';
#define STOP_PART(...)                                                                    \
    do {                                                                                  \
        if (len < n)                                                                      \
            len += (size_t)snprintf(buf + len, n - len, "%s", len ? " or " : "");         \
        if (len < n)                                                                      \
            len += (size_t)snprintf(buf + len, n - len, __VA_ARGS__);                     \
    } while (0)
    if (o->converge)
        STOP_PART("when converged");
    if (o->min_residual > 0.0)
        STOP_PART("at a residual below %g", o->min_residual);
    if (o->min_change > 0.0)
        STOP_PART("when the ropelength falls by less than %g", o->min_change);
    if (o->max_steps > 0)
        STOP_PART("after %ld steps", o->max_steps);
    if (o->max_seconds > 0.0)
        STOP_PART("after %g s (--time)", o->max_seconds);
    if (o->max_work > 0.0)
        STOP_PART("after %g s of work (--work)", o->max_work);
#undef STOP_PART
}

/* What a run was given, in words: "resolution 5, autoscale, stops when
 * converged or after 120 s of work (--work)". */
static void settings_text(const tk_options *o, char *buf, size_t n)
{
    char stops[160], count[64] = "";
    stops_text(o, stops, sizeof stops);
    if (o->resolution > 0.0)
        snprintf(count, sizeof count, "resolution %g, ", o->resolution);
    else if (o->vertices > 0)
        snprintf(count, sizeof count, "%zu vertices, ", o->vertices);
    snprintf(buf, n, "%s%sstops %s", count, o->autoscale ? "autoscale, " : "", stops);
}

static void print_progress(tighten_watch *w, const tk_step_report *s)
{
    char budget[96], residual[32] = "-";
    budget_text(w->opt, s, budget, sizeof budget);
    if (s->step > 0) /* the start has no step to measure */
        snprintf(residual, sizeof residual, "%.3g", s->residual);
    fprintf(stderr, "%sstep %7ld  ropelength %.6f  struts %5zu  kinks %4zu  residual %s  %.1f s%s%s",
            w->terminal ? "\r" : "tightknot: ", s->step, s->ropelength, s->struts, s->kinks,
            residual, s->seconds, budget, w->terminal ? " " : "\n");
    fflush(stderr);
}

/* "-" as an output path: standard output (the report that follows it then
 * goes to standard error, to_stderr_after). */
static FILE *open_output(const char *path)
{
    return strcmp(path, "-") ? fopen(path, "w") : stdout;
}

static int close_output(FILE *f)
{
    return f == stdout ? fflush(f) : fclose(f);
}

/* After an output written to standard output, the rest of what would go
 * there goes to standard error. */
static void to_stderr_after(const char *const out[3])
{
    for (int i = 0; i < 2; i++)
        if (out[i] && !strcmp(out[i], "-")) {
            fflush(stdout);
            dup2(STDERR_FILENO, STDOUT_FILENO);
            return;
        }
}

static int write_vect_file(const char *path, const tk_curve *c)
{
    FILE *f = open_output(path);
    if (!f) {
        fprintf(stderr, "tightknot: cannot write %s: %s\n", path, strerror(errno));
        return EXIT_INPUT;
    }
    tk_error err;
    tk_error_clear(&err);
    int rc = tk_vect_write(c, f, &err);
    if (close_output(f) != 0 && rc == TK_OK)
        rc = tk_error_set(&err, TK_EIO, "closing failed: %s", strerror(errno));
    if (rc) {
        fprintf(stderr, "tightknot: %s: %s\n", path, err.message);
        return EXIT_INPUT;
    }
    return EXIT_OK;
}

static int tighten_progress(const tk_step_report *s, void *user)
{
    tighten_watch *w = user;
    for (size_t k = 0; w->log && k < tk_step_nfields; k++)
        fprintf(w->log, "%.17g%c", tk_field_get(&tk_step_fields[k], s),
                k + 1 < tk_step_nfields ? '\t' : '\n');
    if (w->snapshots && s->step % (long)w->every == 0) {
        char path[4096];
        snprintf(path, sizeof path, "%s/step-%06ld.vect", w->snapshots, s->step);
        if (write_vect_file(path, tk_run_curve(w->run)) != EXIT_OK) {
            w->failed = 1;
            return 1;
        }
    }
    double every = w->terminal ? 0.2 : PLAIN_EVERY;
    if ((w->terminal || w->plain) &&
        (s->seconds - w->last_print >= every || s->step <= 1 || w->last_print < 0.0)) {
        w->last_print = s->seconds;
        print_progress(w, s);
    }
    return 0;
}

static int write_struts_file(const char *path, const char *name, tk_run *run)
{
    size_t ns = 0, nk = 0;
    const tk_strut *st = tk_run_struts(run, &ns);
    const tk_kink *kinks = tk_run_kinks(run, &nk);
    const tk_curve *c = tk_run_curve(run);
    double *pin_force = c->npins ? calloc(c->npins, sizeof *pin_force) : NULL;
    tk_error err;
    if (c->npins && (!pin_force || tk_run_pin_forces(run, pin_force, &err) != TK_OK)) {
        fprintf(stderr, "tightknot: the constraints' forces: %s\n",
                pin_force ? err.message : "out of memory");
        free(pin_force);
        return EXIT_INPUT;
    }
    json_t *o = struts_json(name, c, tk_run_latest(run)->thickness, st, ns, kinks, nk, true,
                            pin_force);
    free(pin_force);
    char *text = tk_json_dump(o, true);
    json_decref(o);
    FILE *f = text ? open_output(path) : NULL;
    int ok = f && fputs(text, f) >= 0 && fputc('\n', f) != EOF;
    if (f && close_output(f) != 0)
        ok = 0;
    free(text);
    if (!ok) {
        fprintf(stderr, "tightknot: cannot write %s: %s\n", path, strerror(errno));
        return EXIT_INPUT;
    }
    return EXIT_OK;
}

/* The basins a run's tightenings reached (tk_json_basins), on a line. */
static void print_basins(json_t *b)
{
    json_t *list = json_object_get(b, "basins"), *one;
    size_t k;
    printf("  basins reached on the final polygon:");
    json_array_foreach(list, k, one)
        printf("%s %.9g (%lld)", k ? "," : "", json_real_value(json_object_get(one, "ropelength")),
               (long long)json_integer_value(json_object_get(one, "times")));
    const char *note = json_string_value(json_object_get(b, "note"));
    printf("%s%s\n", note ? "; the lowest " : "", note ? note : "");
    json_decref(b);
}

static int cmd_tighten(int argc, char **argv)
{
    cli_args a;
    if (parse_args("tighten", argc, argv, CMD_TIGHTEN, &a))
        return EXIT_USAGE;
    if (a.help) {
        fputs(tighten_help, stdout);
        print_run_options(stdout);
        fputs(tighten_help_end, stdout);
        return EXIT_OK;
    }
    if (a.npos != 1)
        return usage_error("tighten", a.npos == 0 ? "no FILE given" : "one FILE only");
    tk_options run_opts = a.run;
    tk_options_complete(&run_opts, &a.given);
    if (run_opts.re_resolve > 0.0 && !(run_opts.resolution > 0.0))
        return usage_error("tighten", "--re-resolve needs --resolution (the vertices per unit "
                                      "ropelength to keep)");
    const char *name = a.pos[0];
    const char *const outputs[3] = {a.output, a.struts_out, a.log_out};
    char path[PATH_MAX];
    const char *input = input_path(name, path);
    /* -o may rewrite a file in place, not the catalogue's file a bare name
     * found */
    if (check_outputs(input, input != name, outputs) != EXIT_OK)
        return EXIT_USAGE;
    tk_error err;
    tk_error_clear(&err);
    tk_curve *c = NULL;
    if (tk_vect_read_file(input, NULL, &c, &err) != TK_OK) {
        report(NULL, &err);
        return EXIT_INPUT;
    }
    for (size_t i = 0; i < a.nconstrain; i++) {
        tk_pin pin;
        bool at_vertex;
        if (tk_pin_parse(a.constrain[i], &pin, &at_vertex, &err) ||
            tk_curve_pin_add(c, &pin, at_vertex, &err)) {
            tk_curve_free(&c);
            return usage_error("tighten", "--constrain: %s", err.message);
        }
    }
    if (a.snapshots && mkdir(a.snapshots, 0777) != 0 && errno != EEXIST) {
        fprintf(stderr, "tightknot: cannot make %s: %s\n", a.snapshots, strerror(errno));
        tk_curve_free(&c);
        return EXIT_INPUT;
    }
    bool terminal = isatty(STDERR_FILENO) != 0;
    tighten_watch w = {terminal, a.progress && !terminal, -1.0, NULL, a.snapshots, a.every, NULL,
                       &run_opts, 0};
    if (a.log_out) {
        w.log = fopen(a.log_out, "w");
        if (!w.log) {
            fprintf(stderr, "tightknot: cannot write %s: %s\n", a.log_out, strerror(errno));
            tk_curve_free(&c);
            return EXIT_INPUT;
        }
        for (size_t k = 0; k < tk_step_nfields; k++)
            fprintf(w.log, "%s%c", tk_step_fields[k].name, k + 1 < tk_step_nfields ? '\t' : '\n');
    }
    tk_run *run = NULL;
    int status = EXIT_OK;
    if (tk_run_new(c, &run_opts, &run, &err) != TK_OK) {
        report(name, &err);
        status = EXIT_INPUT;
        goto done;
    }
    w.run = run;
    char settings[256];
    settings_text(&run_opts, settings, sizeof settings);
    if (w.terminal || w.plain)
        fprintf(stderr, "tightknot: tightening %s: %s\n", name, settings);
    tighten_progress(tk_run_latest(run), &w);
    tk_run_set_progress(run, tighten_progress, &w);
    tk_stop_reason why = TK_STOP_NONE;
    int rc = tk_run_until(run, &why, &err);
    if (w.terminal)
        fputc('\n', stderr);
    if (rc != TK_OK) {
        report(name, &err);
        status = EXIT_INPUT;
    }
    if (w.failed)
        status = EXIT_INPUT;
    if (a.output && write_vect_file(a.output, tk_run_curve(run)) != EXIT_OK)
        status = EXIT_INPUT;
    if (a.struts_out && write_struts_file(a.struts_out, name, run) != EXIT_OK)
        status = EXIT_INPUT;
    to_stderr_after(outputs);
    const tk_step_report *last = tk_run_latest(run);
    const tk_curve *fin = tk_run_curve(run);
    if (a.json) {
        /* the last step's figures, and "steps" as before them */
        json_t *o = json_object();
        json_object_set_new(o, "file", tk_json_text(name));
        json_t *figures = tk_json_step(last);
        json_object_update(o, figures);
        json_decref(figures);
        json_object_set_new(o, "components", json_integer((json_int_t)fin->ncomp));
        json_object_set_new(o, "steps", json_integer((json_int_t)last->step));
        json_object_set_new(o, "options", tk_json_options(&run_opts));
        json_object_set_new(o, "stop_reason", json_string(tk_stop_reason_name(why)));
        json_object_set_new(o, "invariants",
                            json_pack("{s:o, s:o}", "start",
                                      tk_json_invariants(tk_run_type_start(run)), "result",
                                      tk_json_invariants(tk_run_type_latest(run))));
        size_t ne = 0;
        const tk_escape *e = tk_run_escapes(run, &ne);
        json_object_set_new(o, "escapes", tk_json_escapes(e, ne));
        json_object_set_new(o, "basins", tk_json_basins(e, ne, last->ropelength));
        tk_run_timing t;
        tk_run_timing_get(run, &t);
        json_object_set_new(o, "recovery",
                            tk_json_record(tk_recovery_fields, tk_recovery_nfields, &t));
        if (print_json(o) != EXIT_OK)
            status = EXIT_INPUT;
    } else {
        printf("%s: %ld steps in %.2f s (stopped: %s)\n", name, last->step, last->seconds,
               tk_stop_reason_name(why));
        printf("  ropelength %.9g  length %.9g  thickness %.9g  minrad %.9g\n",
               last->ropelength, last->length, last->thickness, last->minrad);
        printf("  vertices %zu  components %zu  struts %zu  kinks %zu  residual %.3g\n",
               fin->nvert, fin->ncomp, last->struts, last->kinks, last->residual);
        printf("  type ");
        print_type(stdout, fin, tk_run_type_latest(run));
        putchar('\n');
        tk_run_timing t;
        tk_run_timing_get(run, &t);
        printf("  recovery: %ld steps undone and taken shorter, %ld rescales of the whole curve",
               t.undone_steps, t.rescales);
        if (t.rescales > 0)
            printf(" (largest by a factor 1 + %.3g)", t.largest_rescale);
        if (t.bent_corrections > 0)
            printf("; %ld correction%s needed steps weighed by their bending",
                   t.bent_corrections, t.bent_corrections == 1 ? "" : "s");
        putchar('\n');
        if (t.length_steps > 0)
            printf("  step control: %ld step%s judged by the length alone (along the motion the "
                   "length over the thickness rose at first order)\n",
                   t.length_steps, t.length_steps == 1 ? "" : "s");
        if (t.corrected_steps > 0)
            printf("  step control: %ld step%s judged after their correction (along curved "
                   "constraints)\n",
                   t.corrected_steps, t.corrected_steps == 1 ? "" : "s");
        size_t ne = 0;
        const tk_escape *e = tk_run_escapes(run, &ne);
        for (size_t k = 0; k < ne; k++) {
            printf("  escape %zu after step %ld: from %.9g, ", k + 1, e[k].step, e[k].from);
            if (e[k].turned)
                printf("turned inside out, ");
            else
                printf("deformed by %.3g diameters, ", e[k].amplitude);
            if (e[k].explored) {
                if (isnan(e[k].coarse))
                    printf("explored, stopped on the coarsest polygon\n");
                else
                    printf("explored: coarsest polygon left at %.9g%s\n", e[k].coarse,
                           e[k].improved ? " (better)" : "");
                continue;
            }
            if (!isnan(e[k].coarse))
                printf("coarsest polygon left at %.9g, ", e[k].coarse);
            if (isnan(e[k].reached))
                printf("stopped before the final polygon\n");
            else
                printf("reached %.9g%s\n", e[k].reached, e[k].improved ? " (better)" : "");
        }
        print_basins(tk_json_basins(e, ne, last->ropelength));
        printf("  settings: %s\n", settings);
    }
done:
    if (w.log && fclose(w.log) != 0) {
        fprintf(stderr, "tightknot: writing %s failed: %s\n", a.log_out, strerror(errno));
        status = EXIT_INPUT;
    }
    tk_run_free(&run);
    tk_curve_free(&c);
    return status;
}

static int cmd_remote(int argc, char **argv)
{
    return tk_remote_main(argc, argv);
}

static int cmd_frames(int argc, char **argv)
{
    return tk_frames_main(argc, argv);
}

static int cmd_help(int argc, char **argv)
{
    if (argc == 0) {
        fputs(main_help, stdout);
        return EXIT_OK;
    }
    if (argc > 1)
        return usage_error("help", "one COMMAND only");
    if (strcmp(argv[0], "info") == 0)
        fputs(info_help, stdout);
    else if (strcmp(argv[0], "struts") == 0)
        fputs(struts_help, stdout);
    else if (strcmp(argv[0], "generate") == 0)
        fputs(generate_help, stdout);
    else if (strcmp(argv[0], "tighten") == 0)
        fputs(tighten_help, stdout);
    else if (strcmp(argv[0], "remote") == 0)
        fputs(tk_remote_help, stdout);
    else if (strcmp(argv[0], "frames") == 0)
        fputs(tk_frames_help, stdout);
    else if (strcmp(argv[0], "help") == 0)
        fputs(main_help, stdout);
    else
        return usage_error("help", "unknown command '%s'", argv[0]);
    return EXIT_OK;
}

/* ------------------------------------------------------------------ main */

typedef struct command {
    const char *name;
    int (*run)(int argc, char **argv);
} command;

static const command commands[] = {
    {"info", cmd_info},
    {"struts", cmd_struts},
    {"generate", cmd_generate},
    {"tighten", cmd_tighten},
    {"remote", cmd_remote},
    {"frames", cmd_frames},
    {"help", cmd_help},
};

/* Output errors (a full disk, a closed pipe) turn success into failure;
 * a command that already failed has said why. */
static int finish(int status)
{
    if ((fflush(stdout) != 0 || ferror(stdout)) && status == EXIT_OK) {
        fprintf(stderr, "tightknot: writing standard output failed: %s\n", strerror(errno));
        return EXIT_INPUT;
    }
    return status;
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fputs(main_help, stderr);
        return EXIT_USAGE;
    }
    const char *name = argv[1];
    if (strcmp(name, "-h") == 0 || strcmp(name, "--help") == 0)
        return finish(cmd_help(0, NULL));
    if (strcmp(name, "--version") == 0)
        return finish(printf("tightknot %s\n", TK_VERSION) < 0 ? EXIT_FAILURE : EXIT_OK);
    for (size_t i = 0; i < sizeof commands / sizeof commands[0]; i++)
        if (strcmp(name, commands[i].name) == 0)
            return finish(commands[i].run(argc - 2, argv + 2));
    return usage_error(NULL, "unknown command '%s'", name);
}
