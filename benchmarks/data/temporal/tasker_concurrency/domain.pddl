; tasker's own: a goal no plan reaches without two actions at once (required concurrency, as
; IPC's match-cellar): the lamp is on only while `hold_lamp` runs, and `inspect` needs it on
; throughout.  A temporal planner that handles concurrency plans inspect inside hold_lamp; a
; task folder refuses such a plan (one robot does one thing at a time).
(define (domain lamp)
  (:requirements :strips :typing :durative-actions)
  (:types robot spot)
  (:predicates (lit ?s - spot) (inspected ?s - spot) (free ?r - robot))
  (:durative-action hold_lamp
    :parameters (?r - robot ?s - spot)
    :duration (= ?duration 10)
    :condition (at start (free ?r))
    :effect (and (at start (lit ?s)) (at start (not (free ?r))) (at end (not (lit ?s))) (at end (free ?r))))
  (:durative-action inspect
    :parameters (?r - robot ?s - spot)
    :duration (= ?duration 3)
    :condition (over all (lit ?s))
    :effect (at end (inspected ?s)))
)
