(define (domain delivery)
  (:requirements :strips :typing :action-costs)
  (:types room item - object)
  (:predicates (robot-at ?r - room) (item-at ?i - item ?r - room) (holding ?i - item) (free))
  (:functions (dist ?a ?b - room) - number (total-cost) - number)
  (:action move
    :parameters (?a ?b - room)
    :precondition (robot-at ?a)
    :effect (and (not (robot-at ?a)) (robot-at ?b) (increase (total-cost) (dist ?a ?b))))
  (:action pick
    :parameters (?i - item ?r - room)
    :precondition (and (robot-at ?r) (item-at ?i ?r) (free))
    :effect (and (holding ?i) (not (item-at ?i ?r)) (not (free)) (increase (total-cost) 1)))
  (:action drop
    :parameters (?i - item ?r - room)
    :precondition (and (robot-at ?r) (holding ?i))
    :effect (and (item-at ?i ?r) (not (holding ?i)) (free) (increase (total-cost) 1)))
)
