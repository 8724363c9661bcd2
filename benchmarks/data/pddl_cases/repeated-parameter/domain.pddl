; a predicate that names its parameter twice, as IPC's logistics00 does: legal PDDL
(define (domain load-in)
  (:requirements :strips)
  (:predicates (box ?x) (truck ?x) (at ?x ?l)
               (in ?obj ?obj))
  (:action load :parameters (?b ?t ?l)
    :precondition (and (box ?b) (truck ?t) (at ?b ?l) (at ?t ?l))
    :effect (and (not (at ?b ?l)) (in ?b ?t))))
