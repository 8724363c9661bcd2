(define (problem fetch) (:domain either-move)
  (:objects r - robot b - box k h - place)
  (:init (at r k) (at b h) (link k h))
  (:goal (holding b)))
