// Inline bodies with mistakes: an unknown joint kind, a fixed joint given a
// coordinate, a moving joint without one, a missing mass, a short vector.
moreau::model! {
    pub struct BadInlineBodies;
    bodies {
        a: { joint: ball(qa), axis: [0, 0, 1], mass: 1 },
        b: { joint: fixed(qb), mass: 1 },
        c: { joint: revolute, axis: [0, 0, 1], mass: 1 },
        d: { joint: revolute(qd), axis: [0, 0, 1] },
        e: { joint: prismatic(qe), axis: [1, 0, 0], mass: 1, com: [0, 0] },
    }
}

fn main() {}
