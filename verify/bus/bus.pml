/* The SAFECASS bus protocol between one provider P and one receiver R (docs/verify.md, "The bus").
 *
 * `safecass verify --bus SYSTEM` writes the constants for each pair of the deployment before this
 * text. It mirrors the rules of middleware/src/receiver.hpp (PeerFreshness, Liveness, the Prover's
 * rules, the ownership and stream checks) as node.cpp and supervisor.cpp use them; the conformance
 * test drives those classes with this model's random runs and compares every decision.
 *
 * Time is discrete: a tick is half a heartbeat period (HB = 2 ticks). Every timer of the protocol
 * is a whole number of periods, so half a period is the coarsest tick that still lets a message
 * arrive between two heartbeats and a check find a bound passed one tick after it is reached.
 *
 * Nothing is absolute, so the state space is finite and the search covers runs of any length:
 * - times are ages in ticks ("sent 3 ticks ago"), each counted up to the largest bound it is
 *   compared with, plus one;
 * - a heartbeat's number is its sending time (one per period: the order is the same);
 * - a stream number is its distance below P's latest of that stream and incarnation, plus one
 *   (0: further ahead than P's latest, a wild number; NONE: the number 0, nothing yet), counted
 *   up to CAPS: numbers CAPS or more behind compare equal (docs/verify.md says why that is safe).
 *
 * Generated constants: S streams P provides to R (0..2); B loss bound, D largest network delay,
 * RS resync spacing, RESUB subscription round, QT proof timeout, all in ticks; CAPS; K
 * (periods of calm after which R must show the truth, P5); WATCH_START (R watches P from its own
 * start: a provider; else once heard: the supervisor); FORGET (R forgets P's process on a loss:
 * the supervisor's heartbeats at a coordinator); LOSS_LEVEL (what R shows while P is lost); the
 * budgets B_* (faults and attacks per run: they bound the search, not time) and the mutants M_*;
 * PS (P settles its own losses within PS ticks of the heal) and SL (R keeps a loss for a settling
 * P at most SL ticks: Liveness::kSettleLimit, scaled down; see docs/verify.md).
 */

#define NONE 255
#define NORMAL 0
#define WARNING 1
#define ERROR 2
#define WILDINC 9      /* an incarnation further ahead of R's clock than kIncarnationMargin */
#define QN 2           /* messages in flight per topic (more are lost: the queue is full) */

/* ---- the provider P ---- */
bool p_alive = true;
byte p_inc = 1;        /* its incarnation (1, 2, ...; WILDINC: started with its clock far ahead) */
byte p_sane = 1;       /* its last sane incarnation */
byte p_phase = 0;      /* ticks since its last heartbeat, modulo HB */
byte p_hb = NONE;      /* age of its last heartbeat (NONE: none sent yet, number 0) */
byte p_truth[2];       /* NORMAL or ERROR */
byte p_err[2];         /* ghost: age of its Error (NONE: Normal) */
byte p_levels[2];      /* ghost, P4: the levels it sent on each stream (bit mask) */
bool p_resync = false; /* a resync request to honour */
bool p_set = false;    /* P holds a peer of its own lost (cut off, it lost them too): its Normal streams
                          show Warning until it hears them again (Heartbeat::settling) */
byte p_seta = NONE;    /* ticks since the heal while P settles (NONE: not settling, or still cut off) */
byte p_hon = NONE;     /* age of its last republish for a request */

/* ---- the network and the attacker ---- */
bool cut = false;      /* P cut off: what it sends, and questions to it, are lost */
bool sub_hb = true;    /* R's subscription to P's heartbeat topic */
bool sub_st = true;    /* R's subscription to P's state topic */
bool taken = false;    /* the subscription gone is held by a member under R's identity: IceStorm still
                          holds it, so R's subscription round does not make it again */
byte down = 0;         /* ghost, P1: ticks since P last reached R: alive, not cut off, R subscribed to its
                          heartbeats; or answering R's question; or a member relayed one of its live
                          process's heartbeats to R (sent `age` ago) */
byte calm = 0;         /* ghost, P5: ticks since anything disturbed the pair */
bool disturbed = false;
/* heartbeats in flight: incarnation, age, listed stream numbers, ticks until delivered */
byte hq_n = 0;
byte hq_inc[QN]; byte hq_age[QN]; byte hq_l0[QN]; byte hq_l1[QN]; byte hq_due[QN]; bool hq_set[QN];
/* state updates in flight: signer (0 P, 1 another member), incarnation, stream, number, level, due */
byte sq_n = 0;
byte sq_who[QN]; byte sq_inc[QN]; byte sq_s[QN]; byte sq_seq[QN]; byte sq_lvl[QN]; byte sq_due[QN];
byte rs_due = NONE;    /* R's resync request on its way to P */
/* what a member at the broker recorded, to replay */
bool rh = false; byte rh_inc; byte rh_age; byte rh_l0; byte rh_l1; bool rh_set;
bool rst = false; byte rst_inc; byte rst_seq; byte rst_lvl;
byte b_crash = B_CRASH; byte b_cut = B_CUT; byte b_unsub = B_UNSUB; byte b_broker = B_BROKER;
byte b_flip = B_FLIP; byte b_replay = B_REPLAY; byte b_forge = B_FORGE; byte b_wild = B_WILD;
byte b_rrestart = B_RRESTART; byte b_drop = B_DROP; byte b_settle = B_SETTLE;

/* ---- the receiver R ---- */
byte r_age = 0;        /* ticks since it started */
byte sub_gone = NONE;  /* ticks since a subscription of R is gone and R's repair of it is due: IceStorm's
                          round for one it no longer holds; for one a member took, the renewal while
                          R holds P lost (NONE: holds both, or a taken one while P is not lost) */
/* PeerFreshness */
byte r_inc = 0;        /* the proven incarnation (0: none) */
bool r_doubt = false;  /* lost since it was proven: believed again only on a new proof */
byte r_hb = NONE; bool r_hbp = false;   /* the last heartbeat taken (its age), from a proof */
byte r_last[2]; bool r_lastp[2];        /* each stream's last number taken, from a proof */
byte r_rtt = 0;        /* the last proof's round trip: heartbeats' ages are read as that much older */
/* Liveness */
byte l_beat = NONE;    /* age (estimated) of the newest heartbeat believed; NONE: never */
byte l_behind = NONE;  /* age (estimated) of the first heartbeat that showed a stream ahead */
bool lost = false;
byte l_hold = NONE;    /* ticks a loss has been kept for P settling (NONE: not kept) */
bool g_proof = false;  /* ghost, P2: a proof came since the loss began */
/* the stand-ins of P's streams */
byte h_inc[2]; byte h_seq[2]; bool h_behind[2]; byte view[2];
byte r_resync = NONE;  /* age of its last request to P to republish */
/* the Prover */
bool q_open = false; byte q_age = NONE;
/* what R shows, and P5's count of its changes since calm */
byte shown[2]; byte shown_any;
byte flips[2];         /* ghost, P5: changes of each stream's level shown since calm (a loss aside) */
byte flips_any;        /* ghost, P5: losses since calm */
bit was_lost;          /* ghost, P5: R was holding P lost when it last showed its view */
bit g_seen;            /* ghost, P5: P began settling while R held it, and R has not lost it since */
bit g_allow;           /* ghost, P5: P settled so: its state changed once more, and R, holding it
                          all along, must show that too (a true change, not a flap) */

byte i, s, need, bf, have, beh, fate, est, nv;
/* always false: each names its property in the text SPIN prints for a violated assertion */
bit P1_fail_safe_bound, P2_no_false_recovery, P3_no_false_normal, P4_ownership, P5_convergence;

#define OLDER(a, b) ((a) == NONE -> (b) : ((b) == NONE -> (a) : ((a) > (b) -> (a) : (b))))
#define AGE(a, cap) a = ((a) == NONE -> NONE : ((a) < (cap) -> (a) + 1 : (cap)))
/* heartbeat ages are counted up to CAPH: every comparison of one is with B + HB or less */
#ifndef CAPH
#define CAPH (B + HB + 2)
#endif
/* the estimated age of what P sent `a` ticks ago: the proof's round trip counted as lateness */
#define EST(a) ((a) + r_rtt < CAPH -> (a) + r_rtt : CAPH)

/* What R shows, and P5's count of its changes: a loss and the recovery from a loss that began since
   calm are the one loss P5 allows (flips_any); a recovery from a loss older than calm is a change */
inline show_view() {
  for (s : 0 .. S - 1) {
    nv = (lost -> LOSS_LEVEL : view[s]);
    if :: nv != shown[s] && !lost && !(was_lost && flips_any > 0) -> flips[s]++ :: else -> skip fi;
    shown[s] = nv
  }
  shown_any = (lost -> LOSS_LEVEL : NORMAL);
  was_lost = lost
}

inline ask() {  /* Prover::ask: one question at a time; again a period after the last */
  if
  :: !q_open && (q_age == NONE || q_age >= HB) -> q_open = true; q_age = 0; printf("@ ask\n")
  :: else -> skip
  fi
}

/* A heartbeat, or a proof's, of incarnation inc sent `age` ticks ago is believed (node.cpp believe). */
inline believe(inc, age, l0, l1, proof, set) {
  need = proof; bf = NONE;
  for (s : 0 .. S - 1) {
    have = (h_inc[s] == inc -> h_seq[s] : NONE);
    beh = ((s == 0 -> l0 : l1) < have);
    if :: beh && (h_behind[s] || lost) -> need = true :: else -> skip fi;
    h_behind[s] = beh;
    if :: beh && bf == NONE -> bf = s :: else -> skip fi
  }
#ifdef M_NOCATCHUP
  bf = NONE;
#endif
  /* Liveness::believed: what counts is when it was sent, not when it came */
#ifdef M_ARRIVAL
  est = 0;
#else
  est = EST(age);
#endif
  /* a stream shown ahead for the first time was sent after the last heartbeat believed before:
     behind since then */
  if
  :: bf == NONE -> l_behind = NONE
  :: bf != NONE && l_behind == NONE -> l_behind = (l_beat == NONE -> est : l_beat)
  :: else -> skip
  fi;
  if :: l_beat == NONE || est < l_beat -> l_beat = est :: else -> skip fi;
  if
#ifndef M_NOSETTLE
  /* P settles its own losses: its state is about to change; kept lost until it has (at most SL) */
  :: lost && l_behind == NONE && l_beat <= B && set && (l_hold == NONE || l_hold < SL) ->
     if :: l_hold == NONE -> l_hold = 0 :: else -> skip fi
#endif
  :: lost && l_behind == NONE && l_beat <= B ->
     assert(P2_no_false_recovery || g_proof);  /* a loss ends only on a proof taken since it began */
     lost = false; l_hold = NONE; printf("@ recovered\n")
  :: else -> skip
  fi;
  if
  :: S > 0 && need && (r_resync == NONE || r_resync >= RS) -> r_resync = 0; rs_due = D; printf("@ resync\n")
  :: else -> skip
  fi
}

/* A heartbeat arrives (node.cpp on_beat: open_heartbeat, PeerFreshness::heartbeat). */
inline on_hb(inc, age, l0, l1, set) {
  printf("@ hb %d %d %d %d %d\n", inc, age, l0, l1, set);
  if
#ifndef M_NOINCBOUND
  :: inc == WILDINC -> printf("@ v refuse\n")
#endif
  :: else ->
     if
     :: r_inc == 0 || inc > r_inc || (inc == r_inc && r_doubt) ->
#ifdef M_UNPROVEN
        if
        :: inc != r_inc -> r_inc = inc; for (s : 0 .. 1) { r_last[s] = NONE; r_lastp[s] = false }
        :: else -> skip
        fi;
        r_doubt = false; r_hb = age; r_hbp = false; r_rtt = 0; printf("@ v accept\n");
        believe(inc, age, l0, l1, false, set)
#else
        printf("@ v unproven\n"); ask()
#endif
     :: inc < r_inc -> printf("@ v refuse\n")
     :: inc == r_inc && !r_doubt && age >= r_hb && r_hbp -> printf("@ v covered\n")
     :: inc == r_inc && !r_doubt && age >= r_hb && !r_hbp -> printf("@ v refuse\n")
     :: inc == r_inc && !r_doubt && age < r_hb ->
        r_hb = age; r_hbp = false; printf("@ v accept\n"); believe(inc, age, l0, l1, false, set)
     fi
  fi
}

/* A state update arrives (node.cpp on_update: ownership, PeerFreshness::stream, apply). */
inline on_st(who, inc, st, seq, lvl) {
  printf("@ st %d %d %d %d %d\n", who, inc, st, seq, lvl);
  if
#ifndef M_NOOWNER
  :: who != 0 -> printf("@ v refuse\n")              /* not the member the system file names */
#endif
  :: else ->
     if
     :: r_inc == 0 || inc > r_inc || (inc == r_inc && r_doubt) -> printf("@ v unproven\n")
     :: inc < r_inc -> printf("@ v refuse\n")
     :: inc == r_inc && !r_doubt && seq >= r_last[st] && r_lastp[st] -> printf("@ v unproven\n")
     :: inc == r_inc && !r_doubt && seq >= r_last[st] && !r_lastp[st] -> printf("@ v refuse\n")
#ifndef M_NOJUMP
     :: inc == r_inc && !r_doubt && seq < r_last[st] && seq == 0 -> printf("@ v refuse\n")  /* jumps too far */
#endif
     :: else ->
        r_last[st] = seq; r_lastp[st] = false; printf("@ v accept\n");
        view[st] = lvl; h_inc[st] = inc; h_seq[st] = seq; h_behind[st] = false;
        if :: !h_behind[0] && !h_behind[1] -> l_behind = NONE :: else -> skip fi   /* Liveness::caught_up: every stream */
     fi
  fi
}

/* P answers R's question with its heartbeat of now (Prover, PeerFreshness::proven). */
inline on_proof() {
  printf("@ proof %d %d %d %d\n", p_inc, p_hb, q_age, p_set);
  q_open = false;
  if
  :: q_age > HB -> printf("@ v late\n")              /* answered too late to date P's heartbeats: asked again */
#ifndef M_NOINCBOUND
  :: p_inc == WILDINC -> printf("@ v refuse\n")
#endif
  :: else ->
     if
     :: p_inc < r_inc -> printf("@ v refuse\n")
     :: else ->
        if
        :: p_inc == r_inc -> if :: p_hb <= r_hb -> r_hb = p_hb; r_hbp = true :: else -> skip fi
        :: else -> r_inc = p_inc; r_hb = p_hb; r_hbp = true;
                   for (s : 0 .. 1) { r_last[s] = NONE; r_lastp[s] = false }
        fi;
        for (s : 0 .. S - 1) {
          if :: r_last[s] > 1 -> r_last[s] = 1; r_lastp[s] = true :: else -> skip fi
        }
        r_doubt = false; g_proof = true; r_rtt = q_age; down = 0; printf("@ v accept\n");   /* P reached R */
        believe(p_inc, 0, 1, 1, true, p_set)
     fi
  fi
}

/* The loss rule (Liveness::check) and what a loss does (node.cpp declare_lost). */
inline watch() {
  if
  :: !lost && (WATCH_START || l_beat != NONE) &&
     ((l_beat == NONE && r_age > B) || (l_beat != NONE && l_beat > B) || (l_behind != NONE && l_behind > B)) ->
     lost = true; l_hold = NONE; g_proof = false; g_seen = 0; flips_any++; printf("@ lost\n");
#ifndef M_NORESUB
     sub_hb = true; sub_st = true; taken = false; sub_gone = NONE;  /* subscribed again under new identities */
#endif
     if
     :: FORGET -> r_inc = 0
     :: else ->
#ifndef M_NOREPROOF
        r_doubt = true
#else
        skip
#endif
     fi
  :: else -> skip
  fi
}

inline hpush(inc, age, l0, l1, set, due) {
  if
  :: hq_n < QN -> hq_inc[hq_n] = inc; hq_age[hq_n] = age; hq_l0[hq_n] = l0; hq_l1[hq_n] = l1;
     hq_set[hq_n] = set; hq_due[hq_n] = due; hq_n++
  :: else -> skip   /* the topic's queue is full: lost */
  fi
}
inline hpop() {
  for (i : 1 .. QN - 1) {
    hq_inc[i - 1] = hq_inc[i]; hq_age[i - 1] = hq_age[i]; hq_l0[i - 1] = hq_l0[i]; hq_l1[i - 1] = hq_l1[i];
    hq_set[i - 1] = hq_set[i]; hq_due[i - 1] = hq_due[i]
  }
  hq_n--; hq_inc[hq_n] = 0; hq_age[hq_n] = 0; hq_l0[hq_n] = 0; hq_l1[hq_n] = 0; hq_set[hq_n] = 0; hq_due[hq_n] = 0
}
inline spush(who, inc, st, seq, lvl, due) {
  if
  :: sq_n < QN -> sq_who[sq_n] = who; sq_inc[sq_n] = inc; sq_s[sq_n] = st; sq_seq[sq_n] = seq;
     sq_lvl[sq_n] = lvl; sq_due[sq_n] = due; sq_n++
  :: else -> skip
  fi
}
inline spop() {
  for (i : 1 .. QN - 1) {
    sq_who[i - 1] = sq_who[i]; sq_inc[i - 1] = sq_inc[i]; sq_s[i - 1] = sq_s[i]; sq_seq[i - 1] = sq_seq[i];
    sq_lvl[i - 1] = sq_lvl[i]; sq_due[i - 1] = sq_due[i]
  }
  sq_n--; sq_who[sq_n] = 0; sq_inc[sq_n] = 0; sq_s[sq_n] = 0; sq_seq[sq_n] = 0; sq_lvl[sq_n] = 0; sq_due[sq_n] = 0
}
inline flush() { do :: hq_n > 0 -> hpop() :: else -> break od; do :: sq_n > 0 -> spop() :: else -> break od }

/* A stream number one further behind (P sent a newer one of its incarnation). */
#define BEHIND(x) x = ((x) == 0 || (x) == NONE -> (x) : ((x) < CAPS -> (x) + 1 : CAPS))

/* P sends the next update of stream st, with fate `fate` (0: now, 1..D: that much later, D+1: lost). */
inline publish(st) {
  for (i : 0 .. QN - 1) {
    if :: i < hq_n && hq_inc[i] == p_inc -> if :: st == 0 -> BEHIND(hq_l0[i]) :: else -> BEHIND(hq_l1[i]) fi
       :: else -> skip fi;
    if :: i < sq_n && sq_inc[i] == p_inc && sq_s[i] == st -> BEHIND(sq_seq[i]) :: else -> skip fi
  }
  if :: r_inc == p_inc -> BEHIND(r_last[st]) :: else -> skip fi;
  if :: h_inc[st] == p_inc -> BEHIND(h_seq[st]) :: else -> skip fi;
  if :: rh && rh_inc == p_inc -> if :: st == 0 -> BEHIND(rh_l0) :: else -> BEHIND(rh_l1) fi :: else -> skip fi;
  if :: rst && rst_inc == p_inc && st == 0 -> BEHIND(rst_seq) :: else -> skip fi;
  p_levels[st] = p_levels[st] | (1 << p_truth[st]); printf("@ pub %d %d\n", st, p_truth[st]);
  if
  :: !cut && sub_st && fate <= D -> spush(0, p_inc, st, 1, p_truth[st], fate)
  :: else -> skip
  fi
}

inline r_restart() {  /* a newcomer: knows nothing, starts toward safe */
  r_age = 0; sub_gone = NONE; r_inc = 0; r_doubt = false; r_hb = NONE; r_hbp = false; r_rtt = 0;
  l_beat = NONE; l_behind = NONE; lost = WATCH_START; l_hold = NONE; g_proof = false;
  for (s : 0 .. 1) { r_last[s] = NONE; r_lastp[s] = false; h_inc[s] = 0; h_seq[s] = NONE; h_behind[s] = false; view[s] = NORMAL }
  r_resync = NONE; q_open = false; q_age = NONE; sub_hb = true; sub_st = true; taken = false; sub_gone = NONE;
  flush();
  printf("@ rstart\n")
}

inline p_restart(inc) {  /* a new process: numbers from 0, Normal, its state published at once */
  printf("@ pstart %d\n", inc);
  p_alive = true; p_inc = inc; p_phase = 0; p_hb = NONE; p_resync = false; p_hon = NONE; p_set = false; p_seta = NONE;
  for (s : 0 .. 1) { p_truth[s] = NORMAL; p_err[s] = NONE }
  for (s : 0 .. S - 1) { publish(s) }
}

inline age_all() {
  AGE(p_hb, CAPH); AGE(r_hb, CAPH); AGE(l_beat, CAPH); AGE(l_behind, CAPH); AGE(rh_age, CAPH);
  for (i : 0 .. QN - 1) { if :: i < hq_n -> AGE(hq_age[i], CAPH) :: else -> skip fi }
  AGE(down, B + HB + 1); for (s : 0 .. 1) { AGE(p_err[s], B + HB + 1) }
  AGE(p_hon, HB); AGE(r_resync, RS); AGE(l_hold, SL);
  if :: p_set && !cut -> p_seta = (p_seta == NONE -> 0 : (p_seta < PS -> p_seta + 1 : PS)) :: else -> p_seta = NONE fi; AGE(q_age, (q_open -> QT : HB)); AGE(r_age, B + 1);
  if :: l_beat != NONE -> r_age = B + 1 :: else -> skip fi;   /* only read before a first heartbeat */ AGE(calm, K * HB); AGE(sub_gone, RESUB);
  for (i : 0 .. QN - 1) {
    if :: i < hq_n && hq_due[i] > 0 -> hq_due[i]-- :: else -> skip fi;
    if :: i < sq_n && sq_due[i] > 0 -> sq_due[i]-- :: else -> skip fi
  }
  if :: rs_due != NONE && rs_due > 0 -> rs_due-- :: else -> skip fi;
  p_phase = (p_phase + 1) % HB;
  printf("@ tick\n")
}

active proctype bus() {
  byte d, fs, ord;
  bool resub = false;
  d_step {
    fs = NONE; lost = WATCH_START;
    for (s : 0 .. 1) { r_last[s] = NONE; h_seq[s] = NONE; p_err[s] = NONE }
    fate = 0; for (s : 0 .. S - 1) { publish(s) }
    show_view()
  }
  do
  :: true ->
     /* 1. at most one fault or attack per tick, within the budgets */
     if
     :: skip
     :: (b_crash > 0 || p_inc == WILDINC) && p_alive ->
        disturbed = true; if :: p_inc != WILDINC -> b_crash-- :: else -> skip fi; p_alive = false; printf("@ crash\n")
     :: !p_alive -> disturbed = true; p_sane++; fs = 0
     :: b_wild > 0 && !p_alive -> disturbed = true; b_wild--; fs = 1
     :: b_flip > 0 && p_alive && p_inc != WILDINC && !p_set && S > 0 -> disturbed = true; b_flip--; d = 0; fs = 2
     :: b_flip > 0 && p_alive && p_inc != WILDINC && !p_set && S > 1 -> disturbed = true; b_flip--; d = 1; fs = 2
     :: b_settle > 0 && cut && p_alive && p_inc != WILDINC && !p_set -> disturbed = true; b_settle--; fs = 4
     :: p_set && p_seta != NONE && p_alive -> fs = 5   /* P hears its own peers again: its own doing, not a fault */
     :: b_wild > 0 && p_alive && S > 0 -> disturbed = true; b_wild--; fs = 3   /* P's own fault: a number far ahead */
     :: b_cut > 0 && !cut -> disturbed = true; b_cut--; cut = true; printf("@ cut\n")
     :: cut -> disturbed = true; cut = false; printf("@ heal\n")
     :: b_unsub > 0 && sub_hb -> disturbed = true; b_unsub--; sub_hb = false; printf("@ unsub hb\n")
     :: b_unsub > 0 && sub_st && S > 0 -> disturbed = true; b_unsub--; sub_st = false; printf("@ unsub st\n")
     :: b_unsub > 0 && sub_hb -> disturbed = true; b_unsub--; sub_hb = false; taken = true; printf("@ take hb\n")
     :: b_unsub > 0 && sub_st && S > 0 -> disturbed = true; b_unsub--; sub_st = false; taken = true; printf("@ take st\n")
     :: b_broker > 0 -> disturbed = true; b_broker--; d_step { flush(); sub_hb = false; sub_st = false; taken = false; rs_due = NONE; printf("@ broker\n") }
     :: b_replay > 0 && rh -> disturbed = true; b_replay--; d_step { printf("@ replay hb\n"); hpush(rh_inc, rh_age, rh_l0, rh_l1, rh_set, 0); if :: p_alive && rh_inc == p_inc && rh_age < down -> down = rh_age :: else -> skip fi }
     :: b_replay > 0 && rst && sub_st -> disturbed = true; b_replay--; d_step { printf("@ replay st\n"); spush(0, rst_inc, 0, rst_seq, rst_lvl, 0) }
     :: b_forge > 0 && S > 0 && sub_st -> disturbed = true; b_forge--; d_step { printf("@ forge\n"); spush(1, p_inc, 0, 1, WARNING, 0) }
     :: b_rrestart > 0 -> disturbed = true; b_rrestart--; d_step { r_restart() }
     fi;
     /* 2. the fate of what P sends this tick: on time, late (at most D ticks), or lost */
     if
     :: fs != NONE || (p_alive && (p_phase == 0 || p_resync)) ->
        if
        :: fate = 0
        :: fate = D
        :: b_drop > 0 -> b_drop--; fate = D + 1
        fi;
        if :: fate == D -> printf("@ late\n") :: fate > D -> printf("@ drop\n") :: else -> skip fi
     :: else -> skip
     fi;
     /* and the order in which the two topics are delivered this tick */
     if :: hq_n > 0 && sq_n > 0 -> ord = 1 :: true -> skip fi;
     /* R's subscription round may come at any tick while a subscription is gone */
     if :: sub_gone != NONE -> resub = true :: true -> skip fi;
     d_step {
       if
       :: fs == 0 -> p_restart(p_sane)
       :: fs == 1 -> p_restart(WILDINC)
       :: fs == 2 -> printf("@ flip %d\n", d); p_truth[d] = ERROR - p_truth[d]; p_err[d] = (p_truth[d] == ERROR -> 0 : NONE); publish(d)
       :: fs == 3 -> printf("@ wild\n"); p_levels[0] = p_levels[0] | (1 << p_truth[0]);
                     if :: !cut && sub_st && fate <= D -> spush(0, p_inc, 0, 0, p_truth[0], fate) :: else -> skip fi
       :: fs == 4 -> printf("@ settling\n"); p_set = true; g_seen = !lost;
                     for (s : 0 .. S - 1) { if :: p_truth[s] == NORMAL -> p_truth[s] = WARNING; publish(s) :: else -> skip fi }
       :: else -> skip
       fi;
       /* P has heard its own peers again (within PS ticks of the heal at the latest) */
       if
       :: fs == 5 || (p_set && p_alive && p_seta == PS) ->
          printf("@ settled\n"); p_set = false; p_seta = NONE; g_allow = g_seen; g_seen = 0;
          for (s : 0 .. S - 1) { if :: p_truth[s] == WARNING -> p_truth[s] = NORMAL; publish(s) :: else -> skip fi }
       :: else -> skip
       fi;
       fs = NONE;
       /* 3. P honours a resync request (one per period), and sends its heartbeat on its period */
       if
       :: p_alive && p_resync && (p_hon == NONE || p_hon >= HB) ->
          p_resync = false; p_hon = 0; for (s : 0 .. S - 1) { publish(s) }
       :: else -> skip
       fi;
       if
       :: p_alive && p_phase == 0 ->
          p_hb = 0; printf("@ beat\n");
          if :: !cut && sub_hb && fate <= D -> hpush(p_inc, 0, 1, 1, p_set, fate) :: else -> skip fi;
          /* a member at the broker keeps the newest heartbeat and update it saw, to replay them */
          if
          :: b_replay > 0 && !cut -> rh = true; rh_inc = p_inc; rh_age = 0; rh_l0 = 1; rh_l1 = 1; rh_set = p_set;
             if :: S > 0 -> rst = true; rst_inc = p_inc; rst_seq = 1; rst_lvl = p_truth[0] :: else -> skip fi
          :: else -> skip
          fi
       :: else -> skip
       fi
     };
     /* 4. R's question is answered, if P is alive and reachable, or fails at its timeout */
     if
     :: q_open && p_alive && !cut && q_age > 0 -> d_step { on_proof() }
     :: q_open && q_age < QT && !(p_alive && !cut && q_age > D) -> skip   /* answered within D when reachable */
     :: q_open && q_age >= QT -> q_open = false; printf("@ noanswer\n")
     :: !q_open -> skip
     fi;
     d_step {
       /* 5. the network delivers what is due, in each topic's order */
       if
       :: ord == 0 ->
          do :: hq_n > 0 && hq_due[0] == 0 -> on_hb(hq_inc[0], hq_age[0], hq_l0[0], hq_l1[0], hq_set[0]); hpop() :: else -> break od;
          do :: sq_n > 0 && sq_due[0] == 0 -> on_st(sq_who[0], sq_inc[0], sq_s[0], sq_seq[0], sq_lvl[0]); spop() :: else -> break od
       :: else ->
          do :: sq_n > 0 && sq_due[0] == 0 -> on_st(sq_who[0], sq_inc[0], sq_s[0], sq_seq[0], sq_lvl[0]); spop() :: else -> break od;
          do :: hq_n > 0 && hq_due[0] == 0 -> on_hb(hq_inc[0], hq_age[0], hq_l0[0], hq_l1[0], hq_set[0]); hpop() :: else -> break od
       fi;
       /* 6. a resync request reaches P */
       if
       :: rs_due == 0 -> if :: p_alive && !cut -> p_resync = true :: else -> skip fi; rs_due = NONE
       :: else -> skip
       fi;
       /* 7. R's subscription round (every RESUB ticks, at any phase): what IceStorm no longer
          holds is made again, with a resync */
#ifndef M_NORESUB
       if
       :: (resub || sub_gone == RESUB) && !taken ->
          sub_hb = true; sub_st = true; rs_due = D; sub_gone = NONE; printf("@ resubscribed\n")
       /* Liveness::renew_due: R holds P lost a round after the loss began (at its start, for a
          newcomer: no loss begins) or after its last renewal, and subscribes again under new
          identities. What a member took before the loss began was renewed as it began; what it
          takes while R holds P lost is renewed within a round, at a tick the model leaves open */
#ifndef M_NORENEW
       :: (resub || sub_gone == RESUB) && taken -> sub_hb = true; sub_st = true; taken = false; sub_gone = NONE; printf("@ renew\n")
#endif
       :: else -> skip
       fi;
#endif
       resub = false;
       if
       :: (!sub_hb || !sub_st) && (!taken || lost) && sub_gone == NONE -> sub_gone = 0
       :: taken && !lost -> sub_gone = NONE   /* renewed only while P is lost: a loss renews it as it begins */
       :: else -> skip
       fi;
       /* 8. the loss rule */
       watch();
       /* the ghosts: since when P is out of reach; calm; what R shows, and how often it changed */
       if :: p_alive && !cut && sub_hb -> down = 0 :: else -> skip fi;
       if :: b_replay == 0 -> rh = false; rh_inc = 0; rh_age = 0; rh_l0 = 0; rh_l1 = 0; rh_set = 0; rst = false; rst_inc = 0; rst_seq = 0; rst_lvl = 0
          :: else -> skip fi;
       if :: disturbed || fate > D || !p_alive || cut -> calm = 0 :: else -> skip fi;   /* a lost subscription is for R to repair */
       disturbed = false;
       show_view();
       if   /* what changed in a tick that disturbed the pair is not counted */
       :: calm == 0 -> for (s : 0 .. 1) { flips[s] = 0 }; flips_any = 0; g_allow = 0
       :: else -> skip
       fi;

       /* P1 (fail-safe bound): out of reach for longer than the bound and a period: lost */
       assert(P1_fail_safe_bound || !(down > B + HB && (WATCH_START || l_beat != NONE)) || lost);
       /* P3 (no false Normal): never Normal for a stream whose truth has been Error for longer */
       for (s : 0 .. S - 1) { assert(P3_no_false_normal || !(shown[s] == NORMAL && p_alive && p_err[s] != NONE && p_err[s] > B + HB)) }
       /* P4 (ownership): what R holds of a stream is a level P sent on it */
       for (s : 0 .. S - 1) { assert(P4_ownership || view[s] == NORMAL || (p_levels[s] & (1 << view[s])) != 0) }
       /* P5 (convergence without flapping): K periods after the last disturbance R shows the
          truth; on its way there it loses P at most once, and takes each stream's level at most once */
       assert(P5_convergence || flips_any <= 1);
       for (s : 0 .. S - 1) {
         assert(P5_convergence || flips[s] <= 1 + g_allow);
         assert(P5_convergence || !(calm >= K * HB && p_inc != WILDINC) || shown[s] == p_truth[s])
       }
       assert(P5_convergence || !(calm >= K * HB && p_inc != WILDINC) || !lost);
       /* the scratch variables back to one value, so that equal states are stored once */
       i = 0; s = 0; need = 0; bf = 0; have = 0; beh = 0; est = 0; nv = 0; fate = 0; ord = 0; d = 0;
       age_all()
     }
  od
}
