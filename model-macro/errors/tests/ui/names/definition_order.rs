moreau::model! {
    pub struct Pendulum;
    coordinates { th: w }
    let tip = l * sin(th);
    let l = 2;
    kinetic = 0.5 * w^2;
    potential = tip;
}

fn main() {}
