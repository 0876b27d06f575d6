/*
 * dds_probe.c - a second DDS participant for the tests of spvs-node --dds.
 *
 *   dds_probe listen OUT MAX_S
 *       Subscribe /cmd_vel and /spvs/state on $ROS_DOMAIN_ID and write one
 *       line per sample to OUT: "T t lx ly lz ax ay az" for a Twist,
 *       "S t seq status v w" for a State (t: seconds since start).  Writes
 *       OUT.ready once a /cmd_vel writer is matched.  Leaves after MAX_S
 *       seconds or on SIGTERM.
 *   dds_probe faults
 *       Write malformed frames on /spvs/matches (count 300 above the
 *       capacity 256, a NaN and an infinite coordinate, count -1) and a
 *       stale one (an older seq after a good frame), and check that each is
 *       answered by one zero Twist and a State of its seq with status
 *       SPVS_E_CAPACITY (-5), SPVS_E_NONFINITE (-3) or SPVS_E_STALE (-8).
 *       Exit 0 when every answer is right.
 */
#define _POSIX_C_SOURCE 200809L

#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "ros_dds.h"
#include "spvs/spvs.h"

static volatile sig_atomic_t g_stop = 0;
static void on_signal(int s) { (void)s; g_stop = 1; }

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

typedef struct {
    dds_entity_t pp, rd_twist, rd_state, wr_matches, ws;
} probe_t;

static int probe_open(probe_t *p)
{
    char err[200];
    uint32_t domain;
    if (spvs_dds_domain(&domain, err, sizeof(err)) != 0 ||
        (p->pp = spvs_dds_participant(domain, err, sizeof(err))) < 0) {
        fprintf(stderr, "dds_probe: %s\n", err);
        return -1;
    }
    dds_qos_t *q = spvs_dds_qos();
    dds_entity_t tt = dds_create_topic(p->pp, &geometry_msgs_msg_dds__Twist__desc,
                                       SPVS_DDS_TOPIC_CMD_VEL, q, NULL);
    dds_entity_t ts = dds_create_topic(p->pp, &spvs_msgs_msg_dds__State__desc,
                                       SPVS_DDS_TOPIC_STATE, q, NULL);
    dds_entity_t tm = dds_create_topic(p->pp, &spvs_msgs_msg_dds__Matches__desc,
                                       SPVS_DDS_TOPIC_MATCHES, q, NULL);
    /* Keep every sample: the tests count them. */
    dds_qset_history(q, DDS_HISTORY_KEEP_ALL, 0);
    p->rd_twist = dds_create_reader(p->pp, tt, q, NULL);
    p->rd_state = dds_create_reader(p->pp, ts, q, NULL);
    p->wr_matches = dds_create_writer(p->pp, tm, q, NULL);
    dds_delete_qos(q);
    p->ws = dds_create_waitset(p->pp);
    if (p->rd_twist < 0 || p->rd_state < 0 || p->wr_matches < 0 || p->ws < 0 ||
        dds_waitset_attach(p->ws, dds_create_readcondition(p->rd_twist, DDS_ANY_STATE), 0) < 0 ||
        dds_waitset_attach(p->ws, dds_create_readcondition(p->rd_state, DDS_ANY_STATE), 1) < 0) {
        fprintf(stderr, "dds_probe: cannot create the DDS entities\n");
        return -1;
    }
    return 0;
}

static int take_twist(probe_t *p, spvs_dds_twist_t *tw)
{
    void *s[1] = { tw };
    dds_sample_info_t info;
    return dds_take(p->rd_twist, s, &info, 1, 1) == 1 && info.valid_data;
}

static int take_state(probe_t *p, spvs_dds_state_t *st)
{
    void *s[1] = { st };
    dds_sample_info_t info;
    return dds_take(p->rd_state, s, &info, 1, 1) == 1 && info.valid_data;
}

static int listen_main(const char *out_path, double max_s)
{
    probe_t p;
    if (probe_open(&p) != 0)
        return 1;
    FILE *out = fopen(out_path, "w");
    if (!out) {
        perror(out_path);
        return 1;
    }
    double t0 = now_s();
    int ready = 0;
    while (!g_stop && now_s() - t0 < max_s) {
        dds_waitset_wait(p.ws, NULL, 0, DDS_MSECS(50));
        if (!ready) {
            dds_subscription_matched_status_t sm;
            if (dds_get_subscription_matched_status(p.rd_twist, &sm) == 0 &&
                sm.current_count > 0) {
                char rp[512];
                snprintf(rp, sizeof(rp), "%s.ready", out_path);
                FILE *r = fopen(rp, "w");
                if (r)
                    fclose(r);
                ready = 1;
            }
        }
        spvs_dds_twist_t tw;
        spvs_dds_state_t st;
        for (int k = 0; k < 64 && take_twist(&p, &tw); k++)
            fprintf(out, "T %.6f %.17g %.17g %.17g %.17g %.17g %.17g\n",
                    now_s() - t0, tw.linear.x, tw.linear.y, tw.linear.z,
                    tw.angular.x, tw.angular.y, tw.angular.z);
        for (int k = 0; k < 64 && take_state(&p, &st); k++)
            fprintf(out, "S %.6f %lld %d %.17g %.17g\n", now_s() - t0,
                    (long long)st.seq, (int)st.status, st.v, st.w);
        fflush(out);
    }
    fclose(out);
    dds_delete(p.pp);
    return 0;
}

/* Send one frame and check its answer: one Twist per send, zero unless
 * any_answer, then the State of its seq with the status wanted (any with
 * any_answer).  The frame goes out again every second while unanswered: the
 * node's reader may not have matched this writer yet, and a volatile reader
 * gets nothing written before that (the simulator's link does the same). */
static int answer_case(probe_t *p, spvs_dds_matches_t *m, int want_status,
                       int any_answer, const char *what)
{
    double t0 = now_s(), t_sent = t0;
    int sends = 1, twists = 0, nonzero = 0;
    dds_write(p->wr_matches, m);
    while (now_s() - t0 < 5.0) {
        if (now_s() - t_sent > 1.0) {
            dds_write(p->wr_matches, m);
            t_sent = now_s();
            sends++;
        }
        dds_waitset_wait(p->ws, NULL, 0, DDS_MSECS(50));
        spvs_dds_twist_t tw;
        spvs_dds_state_t st;
        while (take_twist(p, &tw)) {
            twists++;
            if (tw.linear.x != 0.0 || tw.linear.y != 0.0 || tw.linear.z != 0.0 ||
                tw.angular.x != 0.0 || tw.angular.y != 0.0 || tw.angular.z != 0.0)
                nonzero++;
        }
        while (take_state(p, &st)) {
            if (st.seq != m->seq)
                continue;
            /* The Twist of each answer is written before its State. */
            printf("%s: frame %lld answered with status %d, %d Twist (%d not "
                   "zero) for %d send(s), v %g w %g\n", what,
                   (long long)st.seq, (int)st.status, twists, nonzero, sends,
                   st.v, st.w);
            if (any_answer)
                return twists >= 1 ? 0 : 1;
            return (st.status == want_status && twists >= 1 &&
                    twists <= sends && nonzero == 0 && st.v == 0.0 &&
                    st.w == 0.0) ? 0 : 1;
        }
    }
    printf("%s: no State for frame %lld within 5 s\n", what, (long long)m->seq);
    return 1;
}

static int fault_case(probe_t *p, spvs_dds_matches_t *m, int want_status,
                      const char *what)
{
    return answer_case(p, m, want_status, 0, what);
}

static int faults_main(void)
{
    probe_t p;
    if (probe_open(&p) != 0)
        return 1;
    /* The node's reader must be there before the frames go out. */
    double t0 = now_s();
    for (;;) {
        dds_publication_matched_status_t pm;
        dds_subscription_matched_status_t sm;
        if (dds_get_publication_matched_status(p.wr_matches, &pm) == 0 &&
            dds_get_subscription_matched_status(p.rd_state, &sm) == 0 &&
            pm.current_count > 0 && sm.current_count > 0)
            break;
        if (now_s() - t0 > 10.0) {
            printf("faults: spvs-node --dds not matched within 10 s\n");
            return 1;
        }
        dds_sleepfor(DDS_MSECS(10));
    }
    static spvs_dds_matches_t m;
    memset(&m, 0, sizeof(m));
    m.run_id = 4242;
    for (int i = 0; i < 256; i++) {
        m.feature[i] = i;
        m.x_tgt[i] = m.x_cur[i] = (float)(i % 16) * 20.0f - 150.0f;
        m.y_tgt[i] = m.y_cur[i] = (float)(i / 16) * 15.0f - 120.0f;
    }
    int bad = 0;
    m.seq = 1;
    m.utime = 100000;
    m.count = 300;
    bad += fault_case(&p, &m, SPVS_E_CAPACITY, "count 300 > 256");
    m.seq = 2;
    m.utime = 200000;
    m.count = 40;
    volatile float zero = 0.0f;
    m.x_cur[7] = zero / zero;
    bad += fault_case(&p, &m, SPVS_E_NONFINITE, "NaN x_cur[7]");
    m.seq = 3;
    m.utime = 300000;
    m.x_cur[7] = 1.0f;
    m.y_tgt[12] = 1.0f / zero;
    bad += fault_case(&p, &m, SPVS_E_NONFINITE, "infinite y_tgt[12]");
    m.seq = 4;
    m.utime = 400000;
    m.count = -1;
    bad += fault_case(&p, &m, SPVS_E_CAPACITY, "count -1");
    /* A good frame, then one older than it: stale. */
    m.y_tgt[12] = 1.0f;
    m.count = 40;
    m.seq = 10;
    m.utime = 1000000;
    bad += answer_case(&p, &m, 0, 1, "a good frame");
    m.seq = 9;
    m.utime = 900000;
    bad += fault_case(&p, &m, SPVS_E_STALE, "frame 9 after frame 10");
    dds_delete(p.pp);
    if (bad)
        printf("FAIL: %d malformed frames not answered as they must be\n", bad);
    else
        printf("faults: every malformed frame got one zero Twist and its "
               "status\n");
    return bad ? 1 : 0;
}

int main(int argc, char **argv)
{
    signal(SIGTERM, on_signal);
    signal(SIGINT, on_signal);
    if (argc == 4 && strcmp(argv[1], "listen") == 0)
        return listen_main(argv[2], atof(argv[3]));
    if (argc == 2 && strcmp(argv[1], "faults") == 0)
        return faults_main();
    fprintf(stderr, "usage: dds_probe listen OUT MAX_S | dds_probe faults\n");
    return 2;
}
